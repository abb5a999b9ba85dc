#pragma once
// Coloured point clouds as PLY, the `points3d.ply` that 3DGS reads beside a NeRF-synthetic
// folder's transforms: one "vertex" element with x y z (float or double), optional
// red green blue (uchar; 128 when absent) and any other scalar properties, which are
// skipped. Written as binary little-endian with 3DGS's properties (x y z nx ny nz red
// green blue, normals 0); read as ascii or binary little-endian. Elements after "vertex"
// are ignored; a list property in it, a truncated file, or a non-finite coordinate is an
// InputError naming the file and the field. The count is checked against the file's
// size before anything is allocated.
#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace saresgs {

struct PlyPoint {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  std::array<std::uint8_t, 3> rgb{128, 128, 128};
};

void writePointsPly(const std::string& path, const std::vector<PlyPoint>& points);
std::vector<PlyPoint> readPointsPly(const std::string& path);

}  // namespace saresgs
