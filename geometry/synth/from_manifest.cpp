#include "geometry/synth/from_manifest.h"

#include <nlohmann/json.hpp>

#include <filesystem>

#include "geometry/error.h"
#include "geometry/io/json_file.h"
#include "geometry/io/json_number.h"

namespace saresgs {

std::optional<SyntheticOptions> syntheticOptionsFromManifest(const std::string& folder) {
  const std::string path = (std::filesystem::path(folder) / "manifest.json").string();
  if (!std::filesystem::exists(path)) return std::nullopt;
  const nlohmann::json m = readJsonFile(path);
  if (!m.contains("layout") || !m.contains("objects") || !m["objects"].is_array()) return std::nullopt;
  for (const auto& o : m["objects"]) {
    if (!o.is_object() || (o.contains("mesh") && !o["mesh"].is_string()) || (o.contains("texture") && !o["texture"].is_string()))
      throw InputError(path, "objects", "expected objects whose mesh and texture are strings");
    const std::string mesh = o.value("mesh", ""), tex = o.value("texture", "");
    if (mesh.rfind("procedural:", 0) != 0 || tex.rfind("procedural:", 0) != 0) return std::nullopt;
  }
  // Whole numbers are checked before conversion (1e30 as an int is undefined behaviour).
  for (const char* key : {"width", "height", "num_views"})
    if (m.contains(key) && !(jsonIsExact<int>(m[key]) && m[key].get<int>() >= 0))
      throw InputError(path, key, "expected a whole number >= 0, got " + m[key].dump());
  if (m.contains("seed") && !jsonIsExact<std::uint64_t>(m["seed"]))
    throw InputError(path, "seed", "expected a whole number >= 0, got " + m["seed"].dump());
  try {
    SyntheticOptions s;
    s.layout = m.at("layout");
    s.seed = m.at("seed");
    s.width = m.at("width");
    s.height = m.at("height");
    s.num_views = m.at("num_views");
    s.up_axis = m.value("up_axis", "y");
    s.projection = m.value("projection", "triplanar");
    return s;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, "layout", std::string("incomplete synthetic-scene manifest: ") + e.what());
  }
}

std::optional<SyntheticScene> rebuildSyntheticScene(const std::string& folder, const Scene& dataset) {
  const auto opts = syntheticOptionsFromManifest(folder);
  if (!opts) return std::nullopt;
  SyntheticScene s = makeSyntheticScene(*opts);
  if (s.cameras.size() != dataset.views.size()) return std::nullopt;
  const double tol = 1e-6 * std::max(1.0, dataset.extent);
  for (std::size_t i = 0; i < s.cameras.size(); ++i) {
    // Views are matched by name: the dataset may order them differently.
    const std::string& name = s.names[i];
    const auto it = std::find_if(dataset.views.begin(), dataset.views.end(), [&](const SceneView& v) { return v.name == name; });
    if (it == dataset.views.end() || (it->camera.center() - s.cameras[i].center()).norm() > tol) return std::nullopt;
  }
  return s;
}

}  // namespace saresgs
