#pragma once
// The standard 3DGS .ply layout (as the reference implementation, SuperSplat and
// splat-transform read and write it).
//
// Written: binary little-endian, one element `vertex` with float properties
//   x y z nx ny nz f_dc_0 f_dc_1 f_dc_2 f_rest_0 .. f_rest_{3(K-1)-1}
//   opacity scale_0 scale_1 scale_2 rot_0 rot_1 rot_2 rot_3
// normals are 0; f_rest is channel-major: f_rest_{c*(K-1) + (k-1)} = sh[(i*K + k)*3 + c];
// opacity is the logit, scales the log-scales, rot the quaternion (w, x, y, z), all as
// stored in Gaussians, so a round trip is bit-exact.
//
// Read: properties are matched by name in any order, float or double; other properties
// (any scalar type) and other elements with fixed-size records are skipped. The SH degree
// follows from the number of f_rest properties (0, 9, 24 or 45 -> degree 0..3).
#include <string>

#include "splat/gaussians.h"

namespace saresgs {

// Atomic (temporary file + rename). Throws std::runtime_error naming the file on failure,
// std::invalid_argument when the model's arrays are inconsistent.
void writeGaussiansPly(const std::string& path, const Gaussians& g);

// Throws InputError(file, field, what) on a missing file, a file that is not PLY, a format
// other than binary_little_endian, a missing property (named), an f_rest count other than
// 0/9/24/45, truncated data, or a NaN/Inf value (naming the property and the vertex).
Gaussians readGaussiansPly(const std::string& path);

}  // namespace saresgs
