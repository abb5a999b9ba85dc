#include "geometry/scene/manifest.h"

#include <set>

#include "geometry/error.h"
#include "geometry/io/json_file.h"

namespace saresgs {

DatasetManifest readDatasetManifest(const std::string& path) {
  DatasetManifest m;
  m.path = path;
  const nlohmann::json j = readJsonFile(path);
  jsonObject(j, path, "json");
  if (const auto* b = jsonFind(j, "background", path, "")) {
    m.background_given = true;
    if (!b->is_null()) {
      if (!b->is_array() || b->size() != 3)
        throw InputError(path, "background",
                         "expected an array of 3 numbers in 0..1, or null for none, got " + b->dump());
      std::array<float, 3> c{};
      for (std::size_t k = 0; k < 3; ++k)
        c[k] = static_cast<float>(jsonNumberIn((*b)[k], path, jsonPath("background", k), 0, 1));
      m.background = c;
    }
  }
  for (const char* key : {"width", "height"})
    if (const auto* v = jsonFind(j, key, path, ""))
      (std::string(key) == "width" ? m.width : m.height) =
          static_cast<int>(jsonInteger(*v, path, key, 1, kMaxImageSide));
  if (const auto* v = jsonFind(j, "num_views", path, ""))
    m.num_views = static_cast<int>(jsonInteger(*v, path, "num_views", 1, kMaxSyntheticViews));
  if (const auto* split = jsonFind(j, "split", path, "")) {
    jsonObject(*split, path, "split");
    std::set<std::string> seen;
    for (const char* part : {"train", "test"}) {
      const std::string field = jsonPath("split", part);
      std::vector<std::string> names;
      if (const auto* list = jsonFind(*split, part, path, "split")) names = jsonStrings(*list, path, field);
      for (const std::string& n : names)
        if (!seen.insert(n).second)
          throw InputError(path, field,
                           "names '" + n + "' twice" + (std::string(part) == "test" ? " (or in train as well)" : ""));
      (std::string(part) == "train" ? m.train : m.test) = std::move(names);
    }
  }
  return m;
}

void checkManifestAgainstViews(const DatasetManifest& m, const std::vector<std::string>& names,
                               const std::vector<Intrinsics>& full_size) {
  if (m.num_views && static_cast<std::size_t>(*m.num_views) != names.size())
    throw InputError(m.path, "num_views",
                     std::to_string(*m.num_views) + ", but the dataset has " + std::to_string(names.size()) + " views");
  for (std::size_t i = 0; i < names.size() && i < full_size.size(); ++i) {
    if (m.width && full_size[i].width != *m.width)
      throw InputError(m.path, "width",
                       std::to_string(*m.width) + ", but the camera of " + names[i] + " is " +
                           std::to_string(full_size[i].width) + " wide");
    if (m.height && full_size[i].height != *m.height)
      throw InputError(m.path, "height",
                       std::to_string(*m.height) + ", but the camera of " + names[i] + " is " +
                           std::to_string(full_size[i].height) + " high");
  }
}

}  // namespace saresgs
