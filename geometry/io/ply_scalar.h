#pragma once
// The scalar types of a PLY header's properties (char/int8 ... double/float64), shared by
// the point-cloud reader (geometry/io/point_ply.h) and the Gaussian reader (splat/ply.h).
#include <cstddef>
#include <optional>
#include <string>

namespace saresgs {

enum class PlyScalar { kInt8, kUInt8, kInt16, kUInt16, kInt32, kUInt32, kFloat32, kFloat64 };

// A type's name in either spelling ("uchar" or "uint8", ...); nullopt for any other.
std::optional<PlyScalar> parsePlyScalar(const std::string& name);
// Its size in bytes.
std::size_t plyScalarSize(PlyScalar s);
// A little-endian value of that type at p, as a double.
double loadPlyScalar(const char* p, PlyScalar s);

}  // namespace saresgs
