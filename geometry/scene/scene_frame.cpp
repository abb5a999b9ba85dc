#include "geometry/scene/scene_frame.h"

#include <cmath>

#include "geometry/error.h"
#include "geometry/io/json_file.h"

namespace saresgs {

Camera SceneFrame::toInternal(const Camera& world) const {
  Camera c = world;
  c.t = (world.t + world.R * center) / scale;
  return c;
}

Camera SceneFrame::toWorld(const Camera& internal) const {
  Camera c = internal;
  c.t = internal.t * scale - internal.R * center;
  return c;
}

SceneFrame chooseSceneFrame(double extent, const Eigen::Vector3d& mean_center) {
  SceneFrame f;
  if (!(extent > 0) || !std::isfinite(extent) || !mean_center.allFinite()) return f;
  // std::pow(10.0, k) is exact for 0 <= k <= 22 and the nearest double otherwise.
  f.scale = std::pow(10.0, std::floor(std::log10(extent)));
  if (!(f.scale > 0) || !std::isfinite(f.scale)) return SceneFrame{};
  const double grid = 10.0 * f.scale;
  // + 0.0 turns a rounded -0 into 0 (printed and written as such).
  for (int k = 0; k < 3; ++k) f.center[k] = std::round(mean_center[k] / grid) * grid + 0.0;
  return f;
}

nlohmann::json toJson(const SceneFrame& f) {
  return {{"center", {f.center.x(), f.center.y(), f.center.z()}}, {"scale", f.scale}};
}

SceneFrame sceneFrameFromJson(const nlohmann::json& j, const std::string& file, const std::string& field) {
  const nlohmann::json& o = jsonObject(j, file, field);
  const std::vector<double> c = jsonNumbers(jsonMember(o, "center", file, field), file, jsonPath(field, "center"));
  if (c.size() != 3)
    throw InputError(file, jsonPath(field, "center"), "expected 3 numbers, got " + std::to_string(c.size()));
  SceneFrame f;
  f.center = Eigen::Vector3d(c[0], c[1], c[2]);
  f.scale = jsonNumber(jsonMember(o, "scale", file, field), file, jsonPath(field, "scale"));
  if (!f.center.allFinite()) throw InputError(file, jsonPath(field, "center"), "expected finite numbers");
  if (!(f.scale > 0) || !std::isfinite(f.scale))
    throw InputError(file, jsonPath(field, "scale"), "expected a positive finite number");
  return f;
}

}  // namespace saresgs
