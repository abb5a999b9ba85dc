#pragma once
// The camera-distribution picture of an active run: camera centres and viewing
// directions seen from above and from the side, initial views red, selected green, the
// other candidates grey, test views as hollow marks.
#include <string>
#include <vector>

#include "geometry/image/image.h"
#include "geometry/scene/scene.h"

namespace saresgs {

// The mean up direction of the views (-y of each camera, in world), normalised; world z
// when the views disagree completely. "Above" in both pictures is along it.
Eigen::Vector3d meanCameraUp(const Scene& scene);

Image8 plotCameras(const Scene& scene, const std::vector<int>& initial, const std::vector<int>& selected,
                   int panel_size = 480);

}  // namespace saresgs
