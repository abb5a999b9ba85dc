#pragma once
// The camera-distribution picture of an active run: camera centres and viewing
// directions seen from above and from the side, initial views red, selected green, the
// other candidates grey, test views as hollow marks.
#include <algorithm>
#include <string>
#include <vector>

#include "geometry/image/image.h"
#include "geometry/scene/scene.h"

namespace saresgs {

// The mean up direction of the views (-y of each camera, in world), normalised; world z
// when the views disagree completely. "Above" in both pictures is along it.
Eigen::Vector3d meanCameraUp(const Scene& scene);

// The extent of points seen along two axes (the pictures' framing): extend() with
// everything to be shown, then read the span and centre.
struct PlaneBounds {
  Eigen::Vector3d ax, ay;
  double lo_x = 1e300, hi_x = -1e300, lo_y = 1e300, hi_y = -1e300;
  void extend(const Eigen::Vector3d& p) {
    lo_x = std::min(lo_x, p.dot(ax));
    hi_x = std::max(hi_x, p.dot(ax));
    lo_y = std::min(lo_y, p.dot(ay));
    hi_y = std::max(hi_y, p.dot(ay));
  }
  double span() const { return std::max({hi_x - lo_x, hi_y - lo_y, 1e-9}); }  // the larger side
  double centerX() const { return 0.5 * (lo_x + hi_x); }
  double centerY() const { return 0.5 * (lo_y + hi_y); }
};

Image8 plotCameras(const Scene& scene, const std::vector<int>& initial, const std::vector<int>& selected,
                   int panel_size = 480);

}  // namespace saresgs
