#include "geometry/lifting/correspondence.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <locale>
#include <ostream>
#include <string_view>

#include "geometry/error.h"
#include "geometry/io/atomic_file.h"

namespace saresgs {

namespace {

bool isSpaceInLine(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// Splits on commas and/or blanks. An empty field (",," or a leading/trailing comma) is an
// error: it is almost always a column lost by the program that wrote the file.
bool splitFields(std::string_view line, std::vector<std::string_view>& fields) {
  fields.clear();
  std::size_t i = 0;
  bool need_field = false;  // a comma was seen and no field has followed it yet
  while (i < line.size()) {
    if (isSpaceInLine(line[i])) {
      ++i;
    } else if (line[i] == ',') {
      if (fields.empty() || need_field) return false;
      need_field = true;
      ++i;
    } else {
      std::size_t j = i;
      while (j < line.size() && !isSpaceInLine(line[j]) && line[j] != ',') ++j;
      fields.push_back(line.substr(i, j - i));
      need_field = false;
      i = j;
    }
  }
  return !need_field;
}

bool parseFinite(std::string_view s, double& v) {
  const char* end = s.data() + s.size();
  const auto [ptr, ec] = std::from_chars(s.data(), end, v);
  return ec == std::errc() && ptr == end && std::isfinite(v);
}

std::string quoted(std::string_view line) {
  constexpr std::size_t kMax = 80;
  std::string s(line.substr(0, kMax));
  if (line.size() > kMax) s += "...";
  return "'" + s + "'";
}

}  // namespace

std::vector<Correspondence> readMatches(const std::string& path, const MatchesFileOptions& opts) {
  const std::string text = readFile(path);
  const double shift = 0.5 - opts.pixel_center;
  std::vector<Correspondence> out;
  std::vector<std::string_view> fields;
  bool have_header = false;
  std::size_t line_no = 0, pos = 0;
  while (pos < text.size()) {
    std::size_t eol = text.find('\n', pos);
    if (eol == std::string::npos) eol = text.size();
    std::string_view line(text.data() + pos, eol - pos);
    pos = eol + 1;
    ++line_no;
    std::size_t first = 0;
    while (first < line.size() && isSpaceInLine(line[first])) ++first;
    if (first == line.size() || line[first] == '#') continue;
    const std::string field = "line " + std::to_string(line_no);
    if (!have_header) {
      if (!splitFields(line, fields) || fields.size() != 4 || fields[0] != "x0" || fields[1] != "y0" ||
          fields[2] != "x1" || fields[3] != "y1")
        throw InputError(path, field, "expected the header 'x0,y0,x1,y1', got " + quoted(line));
      have_header = true;
      continue;
    }
    double v[4];
    if (!splitFields(line, fields) || fields.size() != 4 || !parseFinite(fields[0], v[0]) ||
        !parseFinite(fields[1], v[1]) || !parseFinite(fields[2], v[2]) || !parseFinite(fields[3], v[3]))
      throw InputError(path, field, "expected four finite numbers x0,y0,x1,y1, got " + quoted(line));
    out.push_back({Eigen::Vector2d(v[0] + shift, v[1] + shift), Eigen::Vector2d(v[2] + shift, v[3] + shift)});
  }
  if (!have_header) throw InputError(path, "header", "expected the header line 'x0,y0,x1,y1'");
  return out;
}

void writeMatches(const std::string& path, std::span<const Correspondence> matches) {
  writeStreamAtomic(path, [&](std::ostream& os) {
    os.imbue(std::locale::classic());
    os.precision(std::numeric_limits<double>::max_digits10);
    os << "# saresgs matches: view 0 (real) -> view 1 (extrapolated), pixel centres at +0.5\n"
       << "x0,y0,x1,y1\n";
    for (const auto& m : matches) os << m.x0.x() << ',' << m.x0.y() << ',' << m.x1.x() << ',' << m.x1.y() << '\n';
  });
}

std::vector<Correspondence> subsampleByStride(std::span<const Correspondence> matches, int stride, int width,
                                              int height) {
  if (stride < 1) throw InputError("lifting options", "stride", "expected >= 1, got " + std::to_string(stride));
  if (width <= 0 || height <= 0) return {};
  const int nx = (width + stride - 1) / stride, ny = (height + stride - 1) / stride;
  std::vector<std::ptrdiff_t> best(static_cast<std::size_t>(nx) * ny, -1);
  std::vector<double> best_d2(best.size(), 0.0);
  for (std::size_t i = 0; i < matches.size(); ++i) {
    const Eigen::Vector2d& x = matches[i].x0;
    if (!x.allFinite() || !(x.x() >= 0 && x.x() < width && x.y() >= 0 && x.y() < height)) continue;
    const int cx = std::min(static_cast<int>(x.x()) / stride, nx - 1);
    const int cy = std::min(static_cast<int>(x.y()) / stride, ny - 1);
    const Eigen::Vector2d anchor(cx * stride + 0.5, cy * stride + 0.5);
    const double d2 = (x - anchor).squaredNorm();
    const std::size_t cell = static_cast<std::size_t>(cy) * nx + cx;
    if (best[cell] < 0 || d2 < best_d2[cell]) {
      best[cell] = static_cast<std::ptrdiff_t>(i);
      best_d2[cell] = d2;
    }
  }
  std::vector<Correspondence> out;
  for (const auto b : best)
    if (b >= 0) out.push_back(matches[static_cast<std::size_t>(b)]);
  return out;
}

}  // namespace saresgs
