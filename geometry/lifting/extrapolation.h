#pragma once
// Extrapolated cameras for SA-Points (paper Sec. 3.1, Suppl. A.2): the training camera's
// rotation and intrinsics, its centre moved sideways along the camera's own x and y axes
// and backward along its z axis. Moving backward keeps most of the training view inside
// the new frustum, so the two images overlap enough for correspondences.
#include <vector>

#include "geometry/camera/camera.h"

namespace saresgs {

struct ExtrapolationOptions {
  // Offsets as fractions of the scene extent. The paper gives 0.25, 0.25 and 0.5 in
  // Mip-NeRF 360 units, where the extent is about 4.5: 0.25 / 4.5 ~= 0.055, 0.5 / 4.5 ~= 0.11.
  double dx_fraction = 0.055;
  double dy_fraction = 0.055;
  double dz_fraction = 0.11;
  // false: one view, centre moved by (+dx, +dy) and backward. The paper's MASt3R setup
  // uses one extrapolated view without saying which sign; by symmetry any fixed choice
  // is as good, and +x, +y (image right and down) is the first of the eight below.
  // true: the eight views of the paper's DA-v3 setup, "all combinations of perturbation
  // along x and y": (sx, sy) in {-1, 0, +1}^2 without (0, 0), each moved backward by dz.
  // (Only four views would have both offsets non-zero; the paper counts eight, and the
  // z offset is always backward, so the zero offsets must be among the combinations.)
  bool all_combinations = false;
};

// The camera with the same rotation and intrinsics as `cam` whose centre is
// cam.center() + sx * (camera x axis) + sy * (camera y axis) - back * (camera z axis),
// all lengths in world units.
Camera extrapolatedCamera(const Camera& cam, double sx, double sy, double back);

// The extrapolated views of `cam` for a scene of the given extent (see the options), in a
// fixed order: with all_combinations, sy = -1, 0, +1 (outer) then sx = -1, 0, +1 (inner),
// skipping (0, 0), except that the default view (+1, +1) comes first.
std::vector<Camera> extrapolatedCameras(const Camera& cam, double extent, const ExtrapolationOptions& opts = {});

}  // namespace saresgs
