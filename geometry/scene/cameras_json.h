#pragma once
// The reference 3DGS implementation's cameras.json, written beside a model's .ply so
// that splat viewers can show the cameras it was trained from: one entry per view, in the
// dataset's order: {id, img_name (file name without extension), width, height,
// position (camera centre, world), rotation (3x3 camera-to-world rotation, rows, OpenCV
// camera axes: x right, y down, z forward), fx, fy}.
#include <string>

#include <nlohmann/json.hpp>

#include "geometry/scene/scene.h"

namespace saresgs {

nlohmann::json camerasJson(const Scene& scene);
// The scene's background for results.json: {"color": [r, g, b] or null (none), "random":
// bool (a fresh colour per training step; color is then evaluation's), "from": where it
// came from (Scene::background_from)}.
nlohmann::json backgroundJson(const Scene& scene);
// Written atomically (a temporary name, then renamed).
void writeCamerasJson(const std::string& path, const Scene& scene);

}  // namespace saresgs
