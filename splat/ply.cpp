#include "splat/ply.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "geometry/error.h"
#include "geometry/io/atomic_file.h"
#include "geometry/io/byte_order.h"
#include "geometry/io/ply_scalar.h"

namespace saresgs {

namespace {

int fRestCount(int degree) { return 3 * (shCoeffCount(degree) - 1); }

void checkModel(const Gaussians& g) {
  const std::size_t n = g.size();
  if (g.max_sh_degree < 0 || g.max_sh_degree > 3)
    throw std::invalid_argument("writeGaussiansPly: SH degree " + std::to_string(g.max_sh_degree) + " outside 0..3");
  if (g.means.size() != 3 * n || g.log_scales.size() != 3 * n || g.rotations.size() != 4 * n ||
      g.sh.size() != static_cast<std::size_t>(g.shCoeffs()) * 3 * n)
    throw std::invalid_argument("writeGaussiansPly: model arrays disagree on the Gaussian count");
}

// ---- header parsing --------------------------------------------------------------

struct Property {
  std::string name;
  std::string type_name;
  PlyScalar type = PlyScalar::kFloat32;
  bool is_list = false;
  std::size_t offset = 0;  // within the record, for scalar properties
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> props;
  bool has_list = false;
  std::size_t stride = 0;  // bytes per record when no list property
};

struct Header {
  std::vector<Element> elements;
  std::uint64_t data_offset = 0;  // bytes from the start of the file
};

std::string stripCr(std::string s) {
  if (!s.empty() && s.back() == '\r') s.pop_back();
  return s;
}

// The magic line "ply": read at most a few bytes, so that a large binary file is not
// read as a line.
void readMagic(std::istream& in, const std::string& path) {
  char magic[4] = {};
  in.read(magic, 4);
  if (in.gcount() < 3 || std::string(magic, 3) != "ply" || (in.gcount() == 4 && magic[3] != '\n' && magic[3] != '\r'))
    throw InputError(path, "header", "not a PLY file (does not start with the line 'ply')");
  if (magic[3] == '\r' && in.peek() == '\n') in.get();  // "\r\n" line ending
}

// "element NAME COUNT" (after the key).
Element parseElement(std::istringstream& ls, const std::string& line, const std::string& path) {
  Element e;
  std::string count;
  ls >> e.name >> count;
  if (e.name.empty() || count.empty() || count.find_first_not_of("0123456789") != std::string::npos)
    throw InputError(path, "header", "bad element line '" + line + "'");
  try {
    e.count = std::stoull(count);
  } catch (const std::exception&) {
    throw InputError(path, "element " + e.name, "count '" + count + "' out of range");
  }
  return e;
}

// "property TYPE NAME" or "property list COUNT_TYPE ITEM_TYPE NAME" (after the key),
// added to element `e`.
void addProperty(std::istringstream& ls, const std::string& line, const std::string& path, Element& e) {
  Property p;
  std::string type;
  ls >> type;
  if (type == "list") {
    std::string count_type, item_type;
    ls >> count_type >> item_type >> p.name;
    if (!parsePlyScalar(count_type) || !parsePlyScalar(item_type) || p.name.empty())
      throw InputError(path, "header", "bad property line '" + line + "'");
    p.is_list = true;
    e.has_list = true;
  } else {
    const auto t = parsePlyScalar(type);
    ls >> p.name;
    if (!t || p.name.empty()) throw InputError(path, "header", "bad property line '" + line + "'");
    p.type = *t;
    p.type_name = type;
    p.offset = e.stride;
    e.stride += plyScalarSize(p.type);
  }
  for (const auto& q : e.props)
    if (q.name == p.name) throw InputError(path, "property " + p.name, "appears twice in element " + e.name);
  e.props.push_back(std::move(p));
}

Header parseGaussianHeader(std::istream& in, const std::string& path) {
  readMagic(in, path);
  Header h;
  bool have_format = false, ended = false;
  std::size_t header_bytes = 4;
  constexpr std::size_t kMaxHeader = 1 << 20;
  for (std::string line; std::getline(in, line);) {
    header_bytes += line.size() + 1;
    if (header_bytes > kMaxHeader) throw InputError(path, "header", "longer than 1 MiB without end_header");
    line = stripCr(line);
    std::istringstream ls(line);
    std::string key;
    ls >> key;
    if (key.empty() || key == "comment" || key == "obj_info") continue;
    if (key == "end_header") {
      ended = true;
      break;
    }
    if (key == "format") {
      std::string fmt, version;
      ls >> fmt >> version;
      if (fmt != "binary_little_endian")
        throw InputError(path, "format",
                         "found '" + fmt + (version.empty() ? "" : " " + version) + "', expected binary_little_endian");
      have_format = true;
    } else if (key == "element") {
      h.elements.push_back(parseElement(ls, line, path));
    } else if (key == "property") {
      if (h.elements.empty()) throw InputError(path, "header", "property before any element: '" + line + "'");
      addProperty(ls, line, path, h.elements.back());
    } else {
      throw InputError(path, "header", "unknown header line '" + line + "'");
    }
  }
  if (!ended) throw InputError(path, "header", "no end_header line");
  if (!have_format) throw InputError(path, "format", "no format line, expected binary_little_endian");
  // end_header as the very last bytes (no newline, no data) leaves the stream at EOF.
  if (in.eof()) in.clear();
  const auto pos = in.tellg();
  if (pos < 0) throw InputError(path, "header", "cannot locate the end of the header");
  h.data_offset = static_cast<std::uint64_t>(pos);
  return h;
}

// ---- data ------------------------------------------------------------------------

struct Source {
  std::string name;
  std::size_t offset = 0;
  bool is_double = false;
  // The first Gaussian's slot is (*array)[first]: an index, not a pointer, as the arrays
  // of an empty model have no storage to point into.
  std::vector<float>* array = nullptr;
  std::size_t first = 0;
  std::size_t step = 0;  // floats between consecutive Gaussians
};

}  // namespace

void writeGaussiansPly(const std::string& path, const Gaussians& g) {
  checkModel(g);
  const std::size_t n = g.size();
  const int K = g.shCoeffs();
  const int rest = fRestCount(g.max_sh_degree);

  std::string header = "ply\nformat binary_little_endian 1.0\ncomment written by saresgs\n";
  header += "element vertex " + std::to_string(n) + "\n";
  for (const char* p : {"x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"})
    header += std::string("property float ") + p + "\n";
  for (int i = 0; i < rest; ++i) header += "property float f_rest_" + std::to_string(i) + "\n";
  for (const char* p : {"opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"})
    header += std::string("property float ") + p + "\n";
  header += "end_header\n";

  const std::size_t per = 9 + static_cast<std::size_t>(rest) + 8;
  writeStreamAtomic(
      path,
      [&](std::ostream& out) {
        out.write(header.data(), static_cast<std::streamsize>(header.size()));
        std::vector<float> rec(per);
        std::string bytes;
        constexpr std::size_t kChunk = 4096;
        for (std::size_t b = 0; b < n; b += kChunk) {
          bytes.clear();
          for (std::size_t i = b; i < std::min(n, b + kChunk); ++i) {
            std::size_t j = 0;
            for (int a = 0; a < 3; ++a) rec[j++] = g.means[3 * i + a];
            for (int a = 0; a < 3; ++a) rec[j++] = 0.0f;
            for (int c = 0; c < 3; ++c) rec[j++] = g.sh[(i * K) * 3 + c];
            for (int c = 0; c < 3; ++c)
              for (int k = 1; k < K; ++k) rec[j++] = g.sh[(i * K + k) * 3 + c];
            rec[j++] = g.opacities[i];
            for (int a = 0; a < 3; ++a) rec[j++] = g.log_scales[3 * i + a];
            for (int a = 0; a < 4; ++a) rec[j++] = g.rotations[4 * i + a];
            for (float v : rec) byte_order::appendLittleEndian(bytes, v);
          }
          out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        }
      },
      true);
}

Gaussians readGaussiansPly(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "file", "does not exist or cannot be read");
  const Header h = parseGaussianHeader(in, path);
  std::error_code ec;
  const std::uint64_t file_size = std::filesystem::file_size(path, ec);
  if (ec) throw InputError(path, "file", "cannot determine its size");

  // Locate the vertex element; elements before it must have fixed-size records.
  std::uint64_t offset = h.data_offset;
  const Element* vertex = nullptr;
  for (const auto& e : h.elements) {
    if (e.name == "vertex") {
      vertex = &e;
      break;
    }
    if (e.has_list)
      throw InputError(path, "element " + e.name, "has a list property and precedes element vertex; cannot skip it");
    if (e.stride != 0 && e.count > (file_size - std::min(file_size, offset)) / e.stride)
      throw InputError(path, "element " + e.name, "truncated data");
    offset += e.count * e.stride;
  }
  if (!vertex) throw InputError(path, "element vertex", "missing");
  for (const auto& p : vertex->props)
    if (p.is_list) throw InputError(path, "property " + p.name, "list properties in element vertex are not supported");

  auto find = [&](const std::string& name) -> const Property* {
    for (const auto& p : vertex->props)
      if (p.name == name) return &p;
    return nullptr;
  };
  // SH degree from the f_rest properties, which must be f_rest_0 .. f_rest_{n-1}.
  int rest = 0;
  for (const auto& p : vertex->props)
    if (p.name.rfind("f_rest_", 0) == 0) ++rest;
  int degree = -1;
  for (int d = 0; d <= 3; ++d)
    if (fRestCount(d) == rest) degree = d;
  if (degree < 0)
    throw InputError(path, "f_rest", std::to_string(rest) + " f_rest properties, expected 0, 9, 24 or 45");

  const std::uint64_t n = vertex->count;
  const std::size_t stride = vertex->stride;
  const std::uint64_t available = file_size - std::min(file_size, offset);
  if (stride == 0 && n > 0) throw InputError(path, "element vertex", "has no properties");
  if (stride != 0 && n > available / stride)
    throw InputError(path, "vertex data",
                     "truncated: " + std::to_string(n) + " vertices of " + std::to_string(stride) + " bytes need " +
                         std::to_string(n * stride) + " bytes, the file has " + std::to_string(available) +
                         " after the header");

  Gaussians g;
  g.max_sh_degree = degree;
  g.resize(static_cast<std::size_t>(n));
  const int K = g.shCoeffs();

  std::vector<Source> sources;
  auto want = [&](const std::string& name, std::vector<float>& array, std::size_t first, std::size_t step) {
    const Property* p = find(name);
    if (!p) throw InputError(path, name, "property missing from element vertex");
    if (p->type != PlyScalar::kFloat32 && p->type != PlyScalar::kFloat64)
      throw InputError(path, name, "type " + p->type_name + ", expected float or double");
    sources.push_back({name, p->offset, p->type == PlyScalar::kFloat64, &array, first, step});
  };
  for (int a = 0; a < 3; ++a) want(std::string(1, "xyz"[a]), g.means, a, 3);
  for (int c = 0; c < 3; ++c) want("f_dc_" + std::to_string(c), g.sh, c, 3 * K);
  for (int c = 0; c < 3; ++c)
    for (int k = 1; k < K; ++k) want("f_rest_" + std::to_string(c * (K - 1) + (k - 1)), g.sh, k * 3 + c, 3 * K);
  want("opacity", g.opacities, 0, 1);
  for (int a = 0; a < 3; ++a) want("scale_" + std::to_string(a), g.log_scales, a, 3);
  for (int a = 0; a < 4; ++a) want("rot_" + std::to_string(a), g.rotations, a, 4);

  in.clear();
  in.seekg(static_cast<std::streamoff>(offset));
  constexpr std::size_t kChunk = 16384;
  std::vector<char> buf;
  for (std::uint64_t b = 0; b < n; b += kChunk) {
    const std::size_t m = static_cast<std::size_t>(std::min<std::uint64_t>(kChunk, n - b));
    buf.resize(m * stride);
    in.read(buf.data(), static_cast<std::streamsize>(buf.size()));
    if (static_cast<std::size_t>(in.gcount()) != buf.size())
      throw InputError(path, "vertex data", "truncated at vertex " + std::to_string(b));
    for (const Source& s : sources)
      for (std::size_t i = 0; i < m; ++i) {
        const char* p = buf.data() + i * stride + s.offset;
        const std::uint64_t vi = b + i;
        float v;
        if (s.is_double) {
          const double d = byte_order::load<double>(p, std::endian::little);
          if (!std::isfinite(d))
            throw InputError(path, s.name, "vertex " + std::to_string(vi) + " is " + (std::isnan(d) ? "NaN" : "Inf"));
          if (std::abs(d) > std::numeric_limits<float>::max())
            throw InputError(path, s.name, "vertex " + std::to_string(vi) + ": value outside the float range");
          v = static_cast<float>(d);
        } else {
          v = byte_order::load<float>(p, std::endian::little);
          if (!std::isfinite(v))
            throw InputError(path, s.name, "vertex " + std::to_string(vi) + " is " + (std::isnan(v) ? "NaN" : "Inf"));
        }
        (*s.array)[s.first + vi * s.step] = v;
      }
  }
  return g;
}

}  // namespace saresgs
