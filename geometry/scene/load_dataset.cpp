// The dataset loader's dispatch by format (scene.h's loadDataset). Apart from scene.cpp,
// which the format readers use, so that scene.cpp depends on none of them.
#include <filesystem>
#include <string>

#include "geometry/error.h"
#include "geometry/scene/scene.h"

namespace saresgs {

namespace fs = std::filesystem;

Scene loadDataset(const std::string& path, const DatasetOptions& opts) {
  const fs::path p(path);
  if (!fs::exists(p)) throw InputError(path, "dataset", "folder does not exist");
  if (fs::exists(p / "transforms_train.json")) return loadBlenderDataset(path, opts);
  if (fs::exists(p / "transforms.json")) return loadNerfstudioDataset(path, opts);
  return loadColmapDataset(path, opts);
}

}  // namespace saresgs
