// NeRF-synthetic / Blender folders: transforms_train.json and transforms_test.json.
// Poses are camera-to-world in OpenGL axes (x right, y up, z backward); we flip y and
// z to reach OpenCV axes. RGBA images are composited on the chosen background.
#include <cmath>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "geometry/error.h"
#include "geometry/io/json_file.h"
#include "geometry/io/json_number.h"
#include "geometry/scene/scene.h"

namespace saresgs {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

double number(const json& j, const std::string& key, const std::string& file,
              const std::string& where) {
  if (!j.contains(key) || !j[key].is_number())
    throw InputError(file, where + key, "expected a number");
  const double v = j[key].get<double>();
  if (!std::isfinite(v)) throw InputError(file, where + key, "expected a finite number");
  return v;
}

std::string resolveImage(const fs::path& root, const std::string& file_path) {
  fs::path p = root / file_path;
  if (!p.has_extension() || !fs::exists(p)) {
    for (const char* ext : {".png", ".jpg", ".jpeg"})
      if (fs::exists(p.string() + ext)) return p.string() + ext;
  }
  return p.lexically_normal().string();
}

void readSplit(const fs::path& root, const std::string& name, const DatasetOptions& opts,
               Scene& scene, std::vector<int>& split) {
  const std::string file = (root / name).string();
  const json j = readJsonFile(file);
  if (!j.contains("frames") || !j["frames"].is_array())
    throw InputError(file, "frames", "expected an array of frames");
  const int f = std::max(1, opts.load.downscale);
  for (size_t k = 0; k < j["frames"].size(); ++k) {
    const json& fr = j["frames"][k];
    const std::string where = "frames[" + std::to_string(k) + "].";
    if (!fr.contains("file_path") || !fr["file_path"].is_string())
      throw InputError(file, where + "file_path", "expected a string");
    SceneView v;
    v.image_path = resolveImage(root, fr["file_path"].get<std::string>());
    v.name = fs::path(v.image_path).filename().string();
    if (!fs::exists(v.image_path))
      throw InputError(v.image_path, where + "file_path", "image file is missing");

    // Intrinsics: camera_angle_x (NeRF) or fl_x/fl_y/cx/cy/w/h (Instant-NGP style),
    // per frame or per file. Size comes from w/h or from the image itself.
    auto pick = [&](const char* key) -> const json* {
      if (fr.contains(key)) return &fr[key];
      if (j.contains(key)) return &j[key];
      return nullptr;
    };
    // A size is a whole number of pixels, checked before conversion (get<int>() of a string
    // throws nlohmann's message, of 1e30 is undefined behaviour).
    auto pixels = [&](const char* key) {
      const json& v = *pick(key);
      if (!jsonIsExact<int>(v) || v.get<int>() < 1)
        throw InputError(file, (fr.contains(key) ? where : std::string()) + key, "expected a positive whole number of pixels");
      return v.get<int>();
    };
    int w = 0, h = 0;
    if (pick("w") && pick("h")) {
      w = pixels("w");
      h = pixels("h");
    } else {
      const Image8 probe = readImage(v.image_path, true);
      w = probe.width;
      h = probe.height;
    }
    Intrinsics K;
    K.width = w;
    K.height = h;
    if (pick("fl_x")) {
      K.fx = number(fr.contains("fl_x") ? fr : j, "fl_x", file, where);
      K.fy = pick("fl_y") ? number(fr.contains("fl_y") ? fr : j, "fl_y", file, where) : K.fx;
    } else {
      const double ax = number(fr.contains("camera_angle_x") ? fr : j, "camera_angle_x", file, "");
      if (!(ax > 0 && ax < M_PI))
        throw InputError(file, "camera_angle_x", "expected an angle in (0, pi) radians");
      K.fx = K.fy = 0.5 * w / std::tan(0.5 * ax);
    }
    K.cx = pick("cx") ? number(fr.contains("cx") ? fr : j, "cx", file, fr.contains("cx") ? where : "") : 0.5 * w;
    K.cy = pick("cy") ? number(fr.contains("cy") ? fr : j, "cy", file, fr.contains("cy") ? where : "") : 0.5 * h;
    if (!K.valid()) throw InputError(file, where + "intrinsics", "expected positive focal length");

    const json& m = fr.value("transform_matrix", json());
    if (!m.is_array() || m.size() < 3)
      throw InputError(file, where + "transform_matrix", "expected a 4x4 array");
    Eigen::Matrix4d c2w = Eigen::Matrix4d::Identity();
    for (int r = 0; r < 3; ++r) {
      if (!m[r].is_array() || m[r].size() != 4)
        throw InputError(file, where + "transform_matrix", "expected rows of 4 numbers");
      for (int c = 0; c < 4; ++c) {
        if (!m[r][c].is_number())
          throw InputError(file, where + "transform_matrix", "expected numbers");
        c2w(r, c) = m[r][c].get<double>();
      }
    }
    if (!c2w.allFinite()) throw InputError(file, where + "transform_matrix", "NaN or Inf in pose");
    const Eigen::Matrix3d Rc2w = c2w.topLeftCorner<3, 3>() * Eigen::Vector3d(1, -1, -1).asDiagonal();
    Camera cam;
    cam.K = f > 1 ? K.scaled(1.0 / f) : K;
    cam.R = Rc2w.transpose();
    cam.t = -cam.R * c2w.topRightCorner<3, 1>();
    validateCamera(cam, file, where + "transform_matrix");
    v.camera = cam;
    split.push_back(static_cast<int>(scene.views.size()));
    scene.views.push_back(std::move(v));
  }
}

}  // namespace

Scene loadBlenderDataset(const std::string& path, const DatasetOptions& opts) {
  const fs::path root(path);
  Scene scene;
  scene.source = path;
  scene.load = opts.load;
  readSplit(root, "transforms_train.json", opts, scene, scene.train);
  if (fs::exists(root / "transforms_test.json"))
    readSplit(root, "transforms_test.json", opts, scene, scene.test);
  if (scene.train.empty())
    throw InputError((root / "transforms_train.json").string(), "frames", "expected at least one frame");
  scene.background = opts.load.background;
  scene.finalize();  // no sparse points: the AABB spans the train cameras
  return scene;
}

}  // namespace saresgs
