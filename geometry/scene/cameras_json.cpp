#include "geometry/scene/cameras_json.h"

#include <filesystem>

#include "geometry/io/atomic_file.h"

namespace saresgs {

nlohmann::json camerasJson(const Scene& scene) {
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t i = 0; i < scene.views.size(); ++i) {
    // World coordinates, as the .ply files beside it.
    const Camera c = scene.frame.toWorld(scene.views[i].camera);
    const Eigen::Matrix3d c2w = c.R.transpose();
    const Eigen::Vector3d p = c.center();
    nlohmann::json rot = nlohmann::json::array();
    for (int r = 0; r < 3; ++r) rot.push_back({c2w(r, 0), c2w(r, 1), c2w(r, 2)});
    out.push_back({{"id", i},
                   {"img_name", std::filesystem::path(scene.views[i].name).stem().string()},
                   {"width", c.K.width},
                   {"height", c.K.height},
                   {"position", {p.x(), p.y(), p.z()}},
                   {"rotation", rot},
                   {"fy", c.K.fy},
                   {"fx", c.K.fx}});
  }
  return out;
}

void writeCamerasJson(const std::string& path, const Scene& scene) {
  writeFileAtomic(path, camerasJson(scene).dump(1) + "\n");
}

nlohmann::json backgroundJson(const Scene& scene) {
  nlohmann::json j;
  j["color"] = scene.background ? nlohmann::json(*scene.background) : nlohmann::json(nullptr);
  j["random"] = scene.random_background;
  j["from"] = scene.background_from;
  return j;
}

}  // namespace saresgs
