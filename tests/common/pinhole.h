#pragma once
// Intrinsics in one expression, for the tests and fuzz targets that build cameras by hand.
// Kept free of GoogleTest (as ring_scene.h) so that the fuzz targets can use it too.
#include "geometry/camera/camera.h"

namespace saresgs::test {

// A w x h pinhole camera with focal length f on both axes and the principal point at the
// image centre (w / 2, h / 2).
inline Intrinsics pinhole(int w, int h, double f) {
  return Intrinsics{.width = w, .height = h, .fx = f, .fy = f, .cx = 0.5 * w, .cy = 0.5 * h};
}

}  // namespace saresgs::test
