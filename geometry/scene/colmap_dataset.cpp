// A COLMAP folder as a Scene: sparse model + images/ (or images_<f>/) [+ depth/].
#include <algorithm>
#include <filesystem>
#include <map>

#include <nlohmann/json.hpp>

#include "geometry/error.h"
#include "geometry/io/colmap.h"
#include "geometry/io/json_file.h"
#include "geometry/scene/colmap_convert.h"
#include "geometry/scene/scene.h"

namespace saresgs {

namespace fs = std::filesystem;

namespace {

std::string findModelDir(const fs::path& root, const std::string& requested) {
  if (!requested.empty()) {
    const fs::path m = fs::path(requested).is_absolute() ? fs::path(requested) : root / requested;
    return m.string();
  }
  for (const fs::path& c : {root / "sparse" / "0", root / "sparse", root})
    if (fs::exists(c / "cameras.bin") || fs::exists(c / "cameras.txt")) return c.string();
  throw InputError(root.string(), "sparse model",
                   "expected a COLMAP model in sparse/0, sparse or the folder itself, or a "
                   "transforms_train.json (Blender)");
}

std::string modelFile(const std::string& dir, const char* stem) {
  const fs::path bin = fs::path(dir) / (std::string(stem) + ".bin");
  return (fs::exists(bin) ? bin : fs::path(dir) / (std::string(stem) + ".txt")).string();
}

// A dataset written by `saresgs scene` names its split in manifest.json ("split":
// {"train": [names], "test": [names]}); it wins over the every-N-th rule.
bool readManifestSplit(const fs::path& manifest, Scene& scene) {
  if (!fs::exists(manifest)) return false;
  const nlohmann::json j = readJsonFile(manifest.string());
  // null: the data has no background (an enclosed scene).
  if (j.contains("background") && !j["background"].is_null()) {
    const auto& b = j["background"];
    if (!b.is_array() || b.size() != 3 || !b[0].is_number() || !b[1].is_number() || !b[2].is_number())
      throw InputError(manifest.string(), "background", "expected an array of 3 numbers, or null for none");
    scene.background = std::array<float, 3>{b[0].get<float>(), b[1].get<float>(), b[2].get<float>()};
  }
  if (!j.contains("split")) return false;
  if (!j["split"].is_object()) throw InputError(manifest.string(), "split", "expected {\"train\": [names], \"test\": [names]}");
  std::map<std::string, int> index;
  for (int i = 0; i < static_cast<int>(scene.views.size()); ++i) index[scene.views[i].name] = i;
  for (const char* part : {"train", "test"}) {
    const auto& names = j["split"].value(part, nlohmann::json::array());
    if (!names.is_array()) throw InputError(manifest.string(), std::string("split.") + part, "expected an array of image names");
    auto& out = std::string(part) == "train" ? scene.train : scene.test;
    for (const auto& n : names) {
      const auto it = n.is_string() ? index.find(n.get<std::string>()) : index.end();
      if (it == index.end())
        throw InputError(manifest.string(), std::string("split.") + part,
                         "names " + n.dump() + ", which is not an image of the model");
      out.push_back(it->second);
    }
  }
  std::sort(scene.train.begin(), scene.train.end());
  std::sort(scene.test.begin(), scene.test.end());
  if (scene.train.empty()) throw InputError(manifest.string(), "split.train", "expected at least one train image");
  return true;
}

}  // namespace

Intrinsics intrinsicsFromColmap(const ColmapCamera& c, const std::string& file) {
  const std::string field = "camera " + std::to_string(c.id);
  Intrinsics K;
  K.width = static_cast<int>(c.width);
  K.height = static_cast<int>(c.height);
  if (c.model == "SIMPLE_PINHOLE" && c.params.size() == 3) {
    K.fx = K.fy = c.params[0];
    K.cx = c.params[1];
    K.cy = c.params[2];
  } else if (c.model == "PINHOLE" && c.params.size() == 4) {
    K.fx = c.params[0];
    K.fy = c.params[1];
    K.cx = c.params[2];
    K.cy = c.params[3];
  } else {
    throw InputError(file, field + ": model",
                     "model " + c.model +
                         " has lens distortion; saresgs needs SIMPLE_PINHOLE or PINHOLE. "
                         "Undistort first: colmap image_undistorter --image_path IMAGES "
                         "--input_path SPARSE --output_path OUT");
  }
  if (!K.valid())
    throw InputError(file, field, "expected positive focal length and image size");
  return K;
}

ColmapCamera colmapFromIntrinsics(const Intrinsics& K, std::uint32_t id) {
  ColmapCamera c;
  c.id = id;
  c.width = static_cast<std::uint64_t>(K.width);
  c.height = static_cast<std::uint64_t>(K.height);
  if (K.fx == K.fy) {
    c.model = "SIMPLE_PINHOLE";
    c.params = {K.fx, K.cx, K.cy};
  } else {
    c.model = "PINHOLE";
    c.params = {K.fx, K.fy, K.cx, K.cy};
  }
  return c;
}

Scene loadColmapDataset(const std::string& path, const DatasetOptions& opts) {
  const fs::path root(path);
  const std::string model_dir = findModelDir(root, opts.model_dir);
  const ColmapModel model = readColmapModel(model_dir);
  const std::string cam_file = modelFile(model_dir, "cameras");
  const std::string img_file = modelFile(model_dir, "images");
  if (model.images.empty()) throw InputError(img_file, "images", "expected at least one image");

  const int f = std::max(1, opts.load.downscale);
  // A pre-downscaled folder (images_2, _4, _8 as 3DGS tools write) is used when it exists;
  // otherwise images/ is resized on load.
  fs::path image_dir = root / "images";
  if (f > 1 && fs::exists(root / ("images_" + std::to_string(f))))
    image_dir = root / ("images_" + std::to_string(f));

  Scene scene;
  scene.source = path;
  scene.load = opts.load;
  std::vector<const ColmapImage*> sorted;
  for (const auto& [id, im] : model.images) sorted.push_back(&im);
  std::sort(sorted.begin(), sorted.end(),
            [](const ColmapImage* a, const ColmapImage* b) { return a->name < b->name; });
  for (const ColmapImage* im : sorted) {
    SceneView v;
    v.name = im->name;
    const Intrinsics K = intrinsicsFromColmap(model.cameras.at(im->camera_id), cam_file);
    v.camera = Camera::fromQuaternion(f > 1 ? K.scaled(1.0 / f) : K, im->q, im->t);
    validateCamera(v.camera, img_file, "image " + std::to_string(im->id) + " (" + im->name + ")");
    v.image_path = (image_dir / im->name).string();
    if (!fs::exists(v.image_path))
      throw InputError(v.image_path, "image " + std::to_string(im->id),
                       "listed in " + img_file + " but the file is missing");
    const fs::path depth = root / "depth" / (fs::path(im->name).stem().string() + ".pfm");
    if (fs::exists(depth)) v.depth_path = depth.string();
    scene.views.push_back(std::move(v));
  }
  if (!readManifestSplit(root / "manifest.json", scene)) {
    for (int i = 0; i < static_cast<int>(scene.views.size()); ++i)
      ((opts.test_every > 0 && i % opts.test_every == 0) ? scene.test : scene.train).push_back(i);
    if (scene.train.empty()) scene.train.swap(scene.test);  // a single view trains
  }

  scene.points.reserve(model.points.size());
  for (const auto& [id, p] : model.points) scene.points.push_back({p.xyz, p.rgb});
  scene.finalize();
  return scene;
}

}  // namespace saresgs
