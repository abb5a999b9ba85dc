#pragma once
// The ".splat" layout of the antimatter15 WebGL viewer, which most web splat viewers read
// (Spark, SuperSplat, splat-transform): 32 bytes per Gaussian, little-endian,
//   position  3 x float32 (world x, y, z)
//   scale     3 x float32 (exp of the log-scales)
//   colour    4 x uint8   (r, g, b: 0.5 + SH_C0 dc clamped to [0, 1]; a: sigmoid(opacity))
//   rotation  4 x uint8   (w, x, y, z of the unit quaternion, each as 128 + 128 q, clamped)
// It keeps degree 0 only (no view-dependent colour) and quantises colour, opacity and
// rotation to 8 bits: about half the size of a degree-0 .ply and a sixth of a degree-3
// one. The HTML report embeds it when a model's .ply would make the page too large.
#include <cstddef>
#include <string>

#include "splat/gaussians.h"

namespace saresgs {

inline constexpr std::size_t kSplatRecordBytes = 32;

// The records of `g` (in the order given), as one byte string. Throws
// std::invalid_argument when the model's arrays are inconsistent.
std::string splatFileBytes(const Gaussians& g);

}  // namespace saresgs
