#pragma once
// Simulated structure-from-motion for synthetic scenes: what COLMAP would give with
// known poses, without running it. Surface points seen (unoccluded, front-facing, inside
// the image) from at least `min_views` train cameras become 3D points with tracks; the
// 3D position gets Gaussian noise that projects to about `pixel_noise` px of
// reprojection error, and a fraction of points are replaced by outliers in the
// bounding box. The 2D observations are the exact projections of the true points.
#include <cstdint>
#include <vector>

#include "geometry/io/colmap.h"
#include "geometry/synth/synthetic_scene.h"

namespace saresgs {

struct SimulatedSfmOptions {
  std::size_t candidates = 40000;  // surface samples tried
  std::size_t max_points = 12000;  // points kept at most
  int min_views = 2;
  double pixel_noise = 0.5;  // target mean reprojection error, px
  double outlier_fraction = 0.03;
  std::uint64_t seed = 0;
};

// Fills model.points and each image's 2D points. `model` must already hold the
// cameras and images (image id i+1 belongs to scene.cameras[i]); only the images of
// scene.train observe points, as in a reconstruction from the train views.
void simulateSfm(const SyntheticScene& scene, ColmapModel& model, const SimulatedSfmOptions& opts = {});

}  // namespace saresgs
