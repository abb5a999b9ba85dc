#pragma once
// Conversions between COLMAP's model records and our Camera.
#include <string>

#include "geometry/camera/camera.h"
#include "geometry/io/colmap.h"

namespace saresgs {

// SIMPLE_PINHOLE or PINHOLE to Intrinsics; any distorted model is refused with an
// InputError that names `file`, the camera and the undistortion command to run.
Intrinsics intrinsicsFromColmap(const ColmapCamera& c, const std::string& file);
// A PINHOLE (SIMPLE_PINHOLE when fx == fy) record for `K`.
ColmapCamera colmapFromIntrinsics(const Intrinsics& K, std::uint32_t id);

}  // namespace saresgs
