#include "geometry/synth/from_manifest.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <limits>

#include "geometry/error.h"
#include "geometry/io/json_file.h"
#include "geometry/scene/manifest.h"

namespace saresgs {

std::optional<SyntheticOptions> syntheticOptionsFromManifest(const std::string& folder) {
  const std::string path = (std::filesystem::path(folder) / "manifest.json").string();
  if (!std::filesystem::exists(path)) return std::nullopt;
  const nlohmann::json m = readJsonFile(path);
  jsonObject(m, path, "json");
  const nlohmann::json* objects = jsonFind(m, "objects", path, "");
  if (!jsonFind(m, "layout", path, "") || !objects) return std::nullopt;
  jsonArray(*objects, path, "objects");
  const bool two_rooms = jsonString(jsonMember(m, "layout", path, ""), path, "layout") == "tworooms";
  for (std::size_t i = 0; i < objects->size(); ++i) {
    const std::string where = jsonPath("objects", i);
    const nlohmann::json& o = jsonObject((*objects)[i], path, where);
    for (const char* key : {"mesh", "texture"}) {
      const nlohmann::json* v = jsonFind(o, key, path, where);
      // Files given to --mesh / --texture are not recorded well enough to rebuild; the
      // procedural objects and tworooms' built-in cgal: meshes are.
      if (!v) return std::nullopt;
      const std::string src = jsonString(*v, path, jsonPath(where, key));
      if (src.rfind("procedural:", 0) != 0 && !(two_rooms && std::string(key) == "mesh" && src.rfind("cgal:", 0) == 0))
        return std::nullopt;
    }
  }
  // Every value is checked before anything is built: a corrupt count must not become
  // two billion cameras.
  SyntheticOptions s;
  s.layout = jsonString(jsonMember(m, "layout", path, ""), path, "layout");
  s.seed = static_cast<std::uint64_t>(
      jsonInteger(jsonMember(m, "seed", path, ""), path, "seed", 0, std::numeric_limits<long long>::max()));
  s.width = static_cast<int>(jsonInteger(jsonMember(m, "width", path, ""), path, "width", 1, kMaxImageSide));
  s.height = static_cast<int>(jsonInteger(jsonMember(m, "height", path, ""), path, "height", 1, kMaxImageSide));
  s.num_views =
      static_cast<int>(jsonInteger(jsonMember(m, "num_views", path, ""), path, "num_views", 1, kMaxSyntheticViews));
  if (const auto* v = jsonFind(m, "up_axis", path, "")) s.up_axis = jsonString(*v, path, "up_axis");
  if (const auto* v = jsonFind(m, "projection", path, "")) s.projection = jsonString(*v, path, "projection");
  return s;
}

std::optional<SyntheticScene> rebuildSyntheticScene(const std::string& folder, const Scene& dataset) {
  const auto opts = syntheticOptionsFromManifest(folder);
  if (!opts) return std::nullopt;
  if (static_cast<std::size_t>(opts->num_views) != dataset.views.size())
    throw InputError(
        (std::filesystem::path(folder) / "manifest.json").string(), "num_views",
        std::to_string(opts->num_views) + ", but the dataset has " + std::to_string(dataset.views.size()) + " views");
  // The rebuilt meshes are in the manifest's frame, which is the dataset's only when the
  // loader kept it (every scene `saresgs scene` writes: metres, about the origin). A dataset
  // moved out of it has no rebuilt ground truth.
  if (!dataset.frame.identity()) return std::nullopt;
  SyntheticScene s = makeSyntheticScene(*opts);
  if (s.cameras.size() != dataset.views.size()) return std::nullopt;
  const double tol = 1e-6 * std::max(1.0, dataset.extent);
  for (std::size_t i = 0; i < s.cameras.size(); ++i) {
    // Views are matched by name: the dataset may order them differently.
    const std::string& name = s.names[i];
    const auto it =
        std::find_if(dataset.views.begin(), dataset.views.end(), [&](const SceneView& v) { return v.name == name; });
    if (it == dataset.views.end() || (it->camera.center() - s.cameras[i].center()).norm() > tol) return std::nullopt;
  }
  return s;
}

}  // namespace saresgs
