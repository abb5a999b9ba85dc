// A COLMAP folder as a Scene: sparse model + images/ (or images_<f>/) [+ depth/].
#include <algorithm>
#include <filesystem>
#include <map>

#include "geometry/error.h"
#include "geometry/io/colmap.h"
#include "geometry/scene/colmap_convert.h"
#include "geometry/scene/manifest.h"
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
                   "transforms_train.json (Blender) or transforms.json (nerfstudio)");
}

std::string modelFile(const std::string& dir, const char* stem) {
  const fs::path bin = fs::path(dir) / (std::string(stem) + ".bin");
  return (fs::exists(bin) ? bin : fs::path(dir) / (std::string(stem) + ".txt")).string();
}

// A dataset written by `saresgs scene` names its split in manifest.json ("split":
// {"train": [names], "test": [names]}); it wins over the every-N-th rule. Its background
// (null: none) and its size and view count, which the model's cameras must match, are
// read too. Returns whether it named the split.
bool applyManifest(const fs::path& manifest, const std::vector<Intrinsics>& full_size, Scene& scene,
                   BackgroundRule& background) {
  if (!fs::exists(manifest)) return false;
  const DatasetManifest m = readDatasetManifest(manifest.string());
  std::vector<std::string> names;
  for (const SceneView& v : scene.views) names.push_back(v.name);
  checkManifestAgainstViews(m, names, full_size);
  if (m.background_given) {
    background.data_said = true;
    background.data_color = m.background;
    background.data_from = "manifest";
  }
  if (!m.train) return false;
  std::map<std::string, int> index;
  for (int i = 0; i < static_cast<int>(scene.views.size()); ++i) index[scene.views[i].name] = i;
  for (const bool train : {true, false}) {
    const std::vector<std::string>& list = train ? *m.train : *m.test;
    auto& out = train ? scene.train : scene.test;
    for (const std::string& n : list) {
      const auto it = index.find(n);
      if (it == index.end())
        throw InputError(manifest.string(), train ? "split.train" : "split.test",
                         "names '" + n + "', which is not an image of the model");
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
  if (c.width == 0 || c.height == 0 || c.width > kMaxImageSide || c.height > kMaxImageSide)
    throw InputError(file, field,
                     "expected an image size of 1.." + std::to_string(kMaxImageSide) + " per side, got " +
                         std::to_string(c.width) + "x" + std::to_string(c.height));
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
  if (!K.valid()) throw InputError(file, field, "expected positive focal length and image size");
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
  if (f > 1 && fs::exists(root / ("images_" + std::to_string(f)))) image_dir = root / ("images_" + std::to_string(f));

  Scene scene;
  scene.source = path;
  scene.load = opts.load;
  std::vector<const ColmapImage*> sorted;
  for (const auto& [id, im] : model.images) sorted.push_back(&im);
  std::sort(sorted.begin(), sorted.end(), [](const ColmapImage* a, const ColmapImage* b) { return a->name < b->name; });
  std::vector<Intrinsics> full_size;
  for (const ColmapImage* im : sorted) {
    if (!scene.views.empty() && scene.views.back().name == im->name)
      throw InputError(img_file, "image " + std::to_string(im->id) + " (" + im->name + ")",
                       "the image name appears twice");
    SceneView v;
    v.name = im->name;
    const Intrinsics K = intrinsicsFromColmap(model.cameras.at(im->camera_id), cam_file);
    full_size.push_back(K);
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
  // The background: the user's, the manifest's, else white when the images have alpha
  // (settleBackground), else none.
  BackgroundRule background;
  background.said = opts.background;
  if (!applyManifest(root / "manifest.json", full_size, scene, background)) {
    for (int i = 0; i < static_cast<int>(scene.views.size()); ++i)
      ((opts.test_every > 0 && i % opts.test_every == 0) ? scene.test : scene.train).push_back(i);
    if (scene.train.empty()) scene.train.swap(scene.test);  // a single view trains
  }
  settleBackground(scene, background);

  scene.points.reserve(model.points.size());
  for (const auto& [id, p] : model.points) scene.points.push_back({p.xyz, p.rgb});
  scene.finalize();
  moveToOwnFrame(scene);
  return scene;
}

}  // namespace saresgs
