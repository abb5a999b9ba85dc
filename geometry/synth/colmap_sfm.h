#pragma once
// Sparse points from the real COLMAP binary with known poses, the way COLMAP's FAQ
// describes: extract and match SIFT features, write a model with the known cameras and
// poses (image ids taken from COLMAP's database by image name, never by order), then
// `colmap point_triangulator`. Needs `colmap` on the PATH (scripts/install_deps.sh).
#include <string>

#include "geometry/io/colmap.h"
#include "geometry/synth/synthetic_scene.h"

namespace saresgs {

// `dataset_dir` must already hold images/ with every view of `scene`; COLMAP's work
// files go to dataset_dir/colmap/. `known` is the model of cameras and posed images
// (colmapModelOf). Returns the triangulated model, with COLMAP's image ids mapped back
// to `known`'s ids. Throws std::runtime_error with COLMAP's log path when a step fails.
ColmapModel triangulateWithColmap(const SyntheticScene& scene, const std::string& dataset_dir,
                                  const ColmapModel& known);

}  // namespace saresgs
