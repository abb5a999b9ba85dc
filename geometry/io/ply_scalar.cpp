#include "geometry/io/ply_scalar.h"

#include "geometry/io/byte_order.h"

namespace saresgs {

std::optional<PlyScalar> parsePlyScalar(const std::string& t) {
  if (t == "char" || t == "int8") return PlyScalar::kInt8;
  if (t == "uchar" || t == "uint8") return PlyScalar::kUInt8;
  if (t == "short" || t == "int16") return PlyScalar::kInt16;
  if (t == "ushort" || t == "uint16") return PlyScalar::kUInt16;
  if (t == "int" || t == "int32") return PlyScalar::kInt32;
  if (t == "uint" || t == "uint32") return PlyScalar::kUInt32;
  if (t == "float" || t == "float32") return PlyScalar::kFloat32;
  if (t == "double" || t == "float64") return PlyScalar::kFloat64;
  return std::nullopt;
}

std::size_t plyScalarSize(PlyScalar s) {
  switch (s) {
    case PlyScalar::kInt8:
    case PlyScalar::kUInt8:
      return 1;
    case PlyScalar::kInt16:
    case PlyScalar::kUInt16:
      return 2;
    case PlyScalar::kInt32:
    case PlyScalar::kUInt32:
    case PlyScalar::kFloat32:
      return 4;
    case PlyScalar::kFloat64:
      return 8;
  }
  return 0;
}

double loadPlyScalar(const char* p, PlyScalar s) {
  using byte_order::load;
  constexpr auto le = std::endian::little;
  switch (s) {
    case PlyScalar::kInt8:
      return load<std::int8_t>(p, le);
    case PlyScalar::kUInt8:
      return load<std::uint8_t>(p, le);
    case PlyScalar::kInt16:
      return load<std::int16_t>(p, le);
    case PlyScalar::kUInt16:
      return load<std::uint16_t>(p, le);
    case PlyScalar::kInt32:
      return load<std::int32_t>(p, le);
    case PlyScalar::kUInt32:
      return load<std::uint32_t>(p, le);
    case PlyScalar::kFloat32:
      return load<float>(p, le);
    case PlyScalar::kFloat64:
      return load<double>(p, le);
  }
  return 0;
}

}  // namespace saresgs
