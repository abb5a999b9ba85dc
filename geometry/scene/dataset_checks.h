#pragma once
// Plausibility of a loaded dataset's cameras, beyond what each format's reader refuses:
// intrinsics that parse but cannot be what the user meant (a field of view outside
// 1..150 degrees, a principal point outside the image) and views that see none of the
// sparse points. Warnings name the view and the field; a dataset in which no train view
// sees any point at all is refused (nothing could be trained from it).
#include <string>
#include <vector>

#include "geometry/scene/scene.h"

namespace saresgs {

struct DatasetWarning {
  std::string view;   // image name
  std::string field;  // "fx", "fy", "cx", "cy", "points"
  std::string message;
};

// Fields of view people shoot (fisheye 150 degrees to long telephoto 1 degree).
inline constexpr double kMinFovDeg = 1.0, kMaxFovDeg = 150.0;

// The warnings, view by view, in dataset order, then the scene's frame (view "(scene)"):
// "frame" when the train cameras sit more than 100 times their spread from the origin
// (single-precision means lose the scene's detail there), "scale" when they spread over
// less than 50 times the renderer's near plane `near_plane` (splat's RasterSettings
// default; geometry knows nothing of splat, so callers pass theirs). The loaders move every
// dataset into a frame of its own (scene_frame.h), where training is fine in either case;
// "frame" is then still given (in world units) for the .ply files, whose single-precision
// world coordinates keep only that resolution, and "scale" guards scenes built in memory
// in world coordinates. Throws
// InputError(scene.source, "intrinsics or poses", ...) when the scene has points and no
// train view sees any.
std::vector<DatasetWarning> checkDataset(const Scene& scene, double near_plane = 0.01);

// One line per warning (the first `max_lines`, then how many more), for stderr.
std::string formatWarnings(const std::vector<DatasetWarning>& warnings, std::size_t max_lines = 8);

}  // namespace saresgs
