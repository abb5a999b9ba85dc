#include "geometry/io/point_ply.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <optional>
#include <sstream>

#include "geometry/error.h"
#include "geometry/io/atomic_file.h"
#include "geometry/io/byte_order.h"
#include "geometry/io/ply_scalar.h"

namespace saresgs {

namespace {

struct VertexLayout {
  bool ascii = false;
  std::uint64_t count = 0;
  std::vector<PlyScalar> types;
  std::size_t stride = 0;
  int xyz[3] = {-1, -1, -1};
  int rgb[3] = {-1, -1, -1};
  std::size_t data_offset = 0;
};

// The header up to end_header; the vertex element must come first (its data does).
VertexLayout parsePointHeader(const std::string& bytes, const std::string& path) {
  VertexLayout L;
  std::size_t pos = 0;
  auto nextLine = [&]() -> std::optional<std::string> {
    if (pos >= bytes.size() || pos > (1u << 20)) return std::nullopt;
    const std::size_t end = bytes.find('\n', pos);
    std::string line = bytes.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
    pos = end == std::string::npos ? bytes.size() : end + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return line;
  };
  if (nextLine() != "ply") throw InputError(path, "header", "not a PLY file (does not start with the line 'ply')");
  bool format = false, in_vertex = false, seen_element = false;
  static const char* kXyz[3] = {"x", "y", "z"};
  static const char* kRgb[3] = {"red", "green", "blue"};
  while (true) {
    const auto line = nextLine();
    if (!line) throw InputError(path, "header", "no end_header line in the first 1 MiB");
    std::istringstream ls(*line);
    std::string key;
    ls >> key;
    if (key.empty() || key == "comment" || key == "obj_info") continue;
    if (key == "end_header") break;
    if (key == "format") {
      std::string f;
      ls >> f;
      if (f != "ascii" && f != "binary_little_endian")
        throw InputError(path, "format", "expected ascii or binary_little_endian, got '" + f + "'");
      L.ascii = f == "ascii";
      format = true;
    } else if (key == "element") {
      std::string name, count;
      ls >> name >> count;
      if (!seen_element) {
        if (name != "vertex") throw InputError(path, "element " + name, "expected the vertex element first");
        const auto [p, ec] = std::from_chars(count.data(), count.data() + count.size(), L.count);
        if (count.empty() || ec != std::errc() || p != count.data() + count.size())
          throw InputError(path, "element vertex", "expected a count, got '" + count + "'");
      }
      in_vertex = !seen_element;
      seen_element = true;
    } else if (key == "property") {
      if (!seen_element) throw InputError(path, "header", "property before any element: '" + *line + "'");
      if (!in_vertex) continue;
      std::string type, name;
      ls >> type >> name;
      const auto t = parsePlyScalar(type);
      if (type == "list")
        throw InputError(path, "property " + name, "a list property in the vertex element is not supported");
      if (!t || name.empty()) throw InputError(path, "header", "bad property line '" + *line + "'");
      const int index = static_cast<int>(L.types.size());
      for (int k = 0; k < 3; ++k) {
        if (name == kXyz[k]) L.xyz[k] = index;
        if (name == kRgb[k]) {
          if (*t != PlyScalar::kUInt8)
            throw InputError(path, "property " + name, "expected uchar colours, got " + type);
          L.rgb[k] = index;
        }
      }
      L.types.push_back(*t);
      L.stride += plyScalarSize(*t);
    } else {
      throw InputError(path, "header", "unknown header line '" + *line + "'");
    }
  }
  if (!format) throw InputError(path, "format", "no format line");
  if (!seen_element) throw InputError(path, "element vertex", "missing");
  for (int k = 0; k < 3; ++k)
    if (L.xyz[k] < 0) throw InputError(path, std::string("property ") + kXyz[k], "missing from the vertex element");
  L.data_offset = pos;
  return L;
}

}  // namespace

void writePointsPly(const std::string& path, const std::vector<PlyPoint>& points) {
  std::string out = "ply\nformat binary_little_endian 1.0\ncomment written by saresgs\nelement vertex " +
                    std::to_string(points.size()) + "\n";
  for (const char* p : {"x", "y", "z", "nx", "ny", "nz"}) out += std::string("property float ") + p + "\n";
  for (const char* p : {"red", "green", "blue"}) out += std::string("property uchar ") + p + "\n";
  out += "end_header\n";
  for (const PlyPoint& p : points) {
    for (int k = 0; k < 3; ++k) byte_order::appendLittleEndian(out, static_cast<float>(p.xyz[k]));
    for (int k = 0; k < 3; ++k) byte_order::appendLittleEndian(out, 0.0f);
    for (int k = 0; k < 3; ++k) out.push_back(static_cast<char>(p.rgb[k]));
  }
  writeFileAtomic(path, out);
}

std::vector<PlyPoint> readPointsPly(const std::string& path) {
  const std::string bytes = readFile(path);
  const VertexLayout L = parsePointHeader(bytes, path);
  const std::size_t left = bytes.size() - L.data_offset, n_props = L.types.size();
  // Each vertex needs its bytes (binary) or one character and a separator per value (ascii).
  const std::uint64_t least = L.ascii ? 2 * n_props : L.stride;
  if (least == 0 || L.count > left / least)
    throw InputError(
        path, "element vertex",
        std::to_string(L.count) + " vertices cannot fit in the " + std::to_string(left) + " bytes after the header");
  std::vector<PlyPoint> out(L.count);
  std::vector<double> values(n_props);
  std::size_t pos = L.data_offset;
  for (std::uint64_t i = 0; i < L.count; ++i) {
    const std::string where = "vertex " + std::to_string(i);
    if (L.ascii) {
      for (std::size_t k = 0; k < n_props; ++k) {
        while (pos < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[pos]))) ++pos;
        std::size_t end = pos;
        while (end < bytes.size() && !std::isspace(static_cast<unsigned char>(bytes[end]))) ++end;
        const auto [p, ec] = std::from_chars(bytes.data() + pos, bytes.data() + end, values[k]);
        if (pos == end || ec != std::errc() || p != bytes.data() + end)
          throw InputError(path, where,
                           "expected " + std::to_string(n_props) + " numbers, got '" +
                               bytes.substr(pos, std::min<std::size_t>(end - pos, 20)) + "'");
        pos = end;
      }
    } else {
      for (std::size_t k = 0, off = 0; k < n_props; off += plyScalarSize(L.types[k]), ++k)
        values[k] = loadPlyScalar(bytes.data() + pos + off, L.types[k]);
      pos += L.stride;
    }
    PlyPoint& pt = out[i];
    for (int k = 0; k < 3; ++k) {
      pt.xyz[k] = values[static_cast<std::size_t>(L.xyz[k])];
      if (L.rgb[k] >= 0) {
        const double c = values[static_cast<std::size_t>(L.rgb[k])];
        if (!(c >= 0 && c <= 255 && c == std::floor(c))) throw InputError(path, where, "expected colours in 0..255");
        pt.rgb[k] = static_cast<std::uint8_t>(c);
      }
    }
    if (!pt.xyz.allFinite()) throw InputError(path, where, "expected finite x y z, got NaN or Inf");
  }
  return out;
}

}  // namespace saresgs
