// NeRF-synthetic / Blender folders: transforms_train.json and transforms_test.json; and
// nerfstudio folders: one transforms.json (ns-process-data's output).
// Poses are camera-to-world in OpenGL axes (x right, y up, z backward); we flip y and
// z to reach OpenCV axes. RGBA images are composited on the scene's background
// (settleBackground). Optional:
// points3d.ply (3DGS's point cloud), depth/<stem>.pfm, manifest.json (`saresgs scene`).
#include <cmath>
#include <filesystem>
#include <algorithm>
#include <map>
#include <tuple>

#include <nlohmann/json.hpp>

#include "geometry/error.h"
#include "geometry/io/json_file.h"
#include "geometry/io/point_ply.h"
#include "geometry/scene/manifest.h"
#include "geometry/scene/scene.h"

namespace saresgs {

namespace fs = std::filesystem;
using nlohmann::json;

// More frames than any capture holds; a larger array is refused before it is walked.
constexpr std::size_t kMaxFrames = 1000000;

namespace {

std::string resolveImage(const fs::path& root, const std::string& file_path) {
  fs::path p = root / file_path;
  if (!p.has_extension() || !fs::exists(p)) {
    for (const char* ext : {".png", ".jpg", ".jpeg"})
      if (fs::exists(p.string() + ext)) return fs::path(p.string() + ext).lexically_normal().string();
  }
  return p.lexically_normal().string();
}

// Reads one transforms file's frames into scene.views (their indices into `split`);
// `full_size` gets each camera before --downscale, `seen` the images of every split so
// far (an image listed twice, in one split or in two, is an error).
enum class Style { kBlender, kNerfstudio };

// nerfstudio's camera models that are pinhole when their distortion is zero, and the
// distortion keys it writes (absent keys are zero).
bool pinholeWhenUndistorted(const std::string& model) {
  return model == "PINHOLE" || model == "SIMPLE_PINHOLE" || model == "OPENCV" || model == "SIMPLE_RADIAL" ||
         model == "RADIAL";
}
constexpr const char* kDistortionKeys[] = {"k1", "k2", "k3", "k4", "p1", "p2"};

void readSplit(const fs::path& root, const std::string& name, const json& j, Style style, const DatasetOptions& opts,
               Scene& scene, std::vector<int>& split, std::vector<Intrinsics>& full_size,
               std::map<std::string, std::string>& seen) {
  const std::string file = (root / name).string();
  jsonObject(j, file, "json");
  const json& frames = jsonArray(jsonMember(j, "frames", file, ""), file, "frames", kMaxFrames);
  const int f = std::max(1, opts.load.downscale);
  for (size_t k = 0; k < frames.size(); ++k) {
    const json& fr = frames[k];
    const std::string where = jsonPath("frames", k);
    jsonObject(fr, file, where);
    SceneView v;
    const std::string file_path =
        jsonString(jsonMember(fr, "file_path", file, where), file, jsonPath(where, "file_path"));
    v.image_path = resolveImage(root, file_path);
    v.name = fs::path(v.image_path).filename().string();
    if (!fs::exists(v.image_path))
      throw InputError(v.image_path, jsonPath(where, "file_path"), "image file is missing");
    const std::string here = name + " " + where;
    if (const auto [it, fresh] = seen.emplace(v.image_path, here); !fresh)
      throw InputError(file, jsonPath(where, "file_path"),
                       "'" + file_path + "' is listed twice (also as " + it->second + ")");

    // Intrinsics: camera_angle_x (NeRF) or fl_x/fl_y/cx/cy/w/h (Instant-NGP style),
    // per frame or per file. Size comes from w/h or from the image itself.
    auto pick = [&](const char* key) -> std::pair<const json*, std::string> {
      if (const json* x = jsonFind(fr, key, file, where)) return {x, jsonPath(where, key)};
      if (const json* x = jsonFind(j, key, file, "")) return {x, key};
      return {nullptr, key};
    };
    auto number = [&](const char* key) {
      const auto [x, field] = pick(key);
      return jsonNumber(*x, file, field);
    };
    auto side = [&](const char* key) {
      const auto [x, field] = pick(key);
      return static_cast<int>(jsonInteger(*x, file, field, 1, kMaxImageSide));
    };
    int w = 0, h = 0;
    if (pick("w").first && pick("h").first) {
      w = side("w");
      h = side("h");
    } else {
      const Image8 probe = readImage(v.image_path, true);
      w = probe.width;
      h = probe.height;
    }
    Intrinsics K;
    K.width = w;
    K.height = h;
    if (pick("fl_x").first) {
      K.fx = number("fl_x");
      K.fy = pick("fl_y").first ? number("fl_y") : K.fx;
    } else {
      const auto [ax_json, ax_field] = pick("camera_angle_x");
      if (!ax_json) throw InputError(file, "camera_angle_x", "missing (or give fl_x per frame or file)");
      const double ax = jsonNumber(*ax_json, file, ax_field);
      if (!(ax > 0 && ax < M_PI)) throw InputError(file, ax_field, "expected an angle in (0, pi) radians");
      K.fx = K.fy = 0.5 * w / std::tan(0.5 * ax);
    }
    K.cx = pick("cx").first ? number("cx") : 0.5 * w;
    K.cy = pick("cy").first ? number("cy") : 0.5 * h;
    if (!K.valid()) throw InputError(file, where + ".intrinsics", "expected positive focal length");
    if (style == Style::kNerfstudio) {
      // nerfstudio: camera_model (default pinhole) and OpenCV distortion, per frame or file.
      std::string model = "PINHOLE";
      std::string model_field = "camera_model";
      if (const auto [x, field] = pick("camera_model"); x) {
        model = jsonString(*x, file, field);
        model_field = field;
      }
      if (!pinholeWhenUndistorted(model))
        throw InputError(file, model_field,
                         "camera model '" + model +
                             "' is not a pinhole camera: saresgs trains pinhole images (PINHOLE, "
                             "SIMPLE_PINHOLE, or OPENCV / SIMPLE_RADIAL / RADIAL with zero distortion); undistort the "
                             "images first (colmap image_undistorter)");
      for (const char* key : kDistortionKeys)
        if (const auto [x, field] = pick(key); x) {
          const double d = jsonNumber(*x, file, field);
          if (d != 0)
            throw InputError(file, field,
                             "distortion " + std::string(key) + " = " + std::to_string(d) + " of camera model " +
                                 model +
                                 " is not zero: saresgs trains pinhole images and does not undistort; undistort them "
                                 "first (colmap image_undistorter), or write 0 if they already are");
        }
    }

    const std::string mfield = jsonPath(where, "transform_matrix");
    const json& m = jsonArray(jsonMember(fr, "transform_matrix", file, where), file, mfield, 4);
    if (m.size() < 3) throw InputError(file, mfield, "expected a 4x4 array");
    Eigen::Matrix4d c2w = Eigen::Matrix4d::Identity();
    for (int r = 0; r < 3; ++r) {
      const std::string row = jsonPath(mfield, static_cast<std::size_t>(r));
      if (jsonArray(m[r], file, row).size() != 4) throw InputError(file, row, "expected a row of 4 numbers");
      for (int c = 0; c < 4; ++c) c2w(r, c) = jsonNumber(m[r][c], file, jsonPath(row, static_cast<std::size_t>(c)));
    }
    const Eigen::Matrix3d Rc2w = c2w.topLeftCorner<3, 3>() * Eigen::Vector3d(1, -1, -1).asDiagonal();
    Camera cam;
    cam.K = f > 1 ? K.scaled(1.0 / f) : K;
    cam.R = Rc2w.transpose();
    cam.t = -cam.R * c2w.topRightCorner<3, 1>();
    validateCamera(cam, file, mfield);
    v.camera = cam;
    const fs::path depth = root / "depth" / (fs::path(v.image_path).stem().string() + ".pfm");
    if (fs::exists(depth)) v.depth_path = depth.string();
    split.push_back(static_cast<int>(scene.views.size()));
    full_size.push_back(K);
    scene.views.push_back(std::move(v));
  }
}

}  // namespace

Scene loadBlenderDataset(const std::string& path, const DatasetOptions& opts) {
  const fs::path root(path);
  Scene scene;
  scene.source = path;
  scene.load = opts.load;
  std::vector<Intrinsics> full_size;
  std::map<std::string, std::string> seen;
  readSplit(root, "transforms_train.json", readJsonFile((root / "transforms_train.json").string()), Style::kBlender,
            opts, scene, scene.train, full_size, seen);
  if (fs::exists(root / "transforms_test.json"))
    readSplit(root, "transforms_test.json", readJsonFile((root / "transforms_test.json").string()), Style::kBlender,
              opts, scene, scene.test, full_size, seen);
  if (scene.train.empty())
    throw InputError((root / "transforms_train.json").string(), "frames", "expected at least one frame");
  // The format implies white (NeRF-synthetic's images are composited on it). A folder
  // written by `saresgs scene --format blender`: its manifest's sizes must match, and a
  // room's "background": null means the data has none (its split is the transforms').
  BackgroundRule rule;
  rule.said = opts.background;
  rule.data_said = true;
  rule.data_color = std::array<float, 3>{1, 1, 1};
  rule.data_from = "Blender (white)";
  if (fs::exists(root / "manifest.json")) {
    const DatasetManifest m = readDatasetManifest((root / "manifest.json").string());
    std::vector<std::string> names;
    for (const SceneView& v : scene.views) names.push_back(v.name);
    checkManifestAgainstViews(m, names, full_size);
    if (m.background_given) {
      rule.data_color = m.background;
      rule.data_from = "manifest";
    }
  }
  settleBackground(scene, rule);
  // 3DGS's points3d.ply beside the transforms, when there is one.
  if (fs::exists(root / "points3d.ply"))
    for (const PlyPoint& p : readPointsPly((root / "points3d.ply").string())) scene.points.push_back({p.xyz, p.rgb});
  scene.finalize();  // without points the AABB spans the train cameras
  moveToOwnFrame(scene);
  return scene;
}

Scene loadNerfstudioDataset(const std::string& path, const DatasetOptions& opts) {
  const fs::path root(path);
  const std::string file = (root / "transforms.json").string();
  const json j = readJsonFile(file);
  Scene scene;
  scene.source = path;
  scene.load = opts.load;
  std::vector<Intrinsics> full_size;
  std::map<std::string, std::string> seen;
  std::vector<int> all;
  readSplit(root, "transforms.json", j, Style::kNerfstudio, opts, scene, all, full_size, seen);
  if (all.empty()) throw InputError(file, "frames", "expected at least one frame");

  // applied_transform (what ns-process-data applied to COLMAP's world; the poses and the
  // points are already in its frame): checked, not needed to train.
  if (const json* a = jsonFind(j, "applied_transform", file, "")) {
    const json& rows = jsonArray(*a, file, "applied_transform", 4);
    if (rows.size() < 3) throw InputError(file, "applied_transform", "expected a 3x4 or 4x4 array");
    for (std::size_t r = 0; r < rows.size(); ++r) {
      const std::string row = jsonPath("applied_transform", r);
      if (jsonArray(rows[r], file, row, 4).size() != 4) throw InputError(file, row, "expected a row of 4 numbers");
      for (std::size_t c = 0; c < 4; ++c) jsonNumber(rows[r][c], file, jsonPath(row, c));
    }
  }

  // The split: nerfstudio's train_filenames / test_filenames (or val_filenames) when
  // given, else every test_every-th view by name, as for COLMAP.
  std::map<std::string, int> by_path;  // file_path as written, and the resolved path
  const json& frames = j["frames"];
  for (std::size_t k = 0; k < frames.size(); ++k) {
    by_path[frames[k]["file_path"].get<std::string>()] = all[k];
    by_path[scene.views[static_cast<std::size_t>(all[k])].image_path] = all[k];
  }
  if (const json* tr = jsonFind(j, "train_filenames", file, "")) {
    const char* test_key = jsonFind(j, "test_filenames", file, "") ? "test_filenames" : "val_filenames";
    const json* te = jsonFind(j, test_key, file, "");
    if (!te)
      throw InputError(file, "test_filenames",
                       "train_filenames is given, so test_filenames (or val_filenames) must be");
    for (const auto& [list, key, out] :
         {std::tuple{tr, "train_filenames", &scene.train}, std::tuple{te, test_key, &scene.test}}) {
      const json& names = jsonArray(*list, file, key, kMaxFrames);
      for (std::size_t k = 0; k < names.size(); ++k) {
        const std::string n = jsonString(names[k], file, jsonPath(key, k));
        auto it = by_path.find(n);
        if (it == by_path.end()) it = by_path.find((root / n).lexically_normal().string());
        if (it == by_path.end())
          throw InputError(file, jsonPath(key, k), "'" + n + "' is not the file_path of any frame");
        out->push_back(it->second);
      }
      std::sort(out->begin(), out->end());
      out->erase(std::unique(out->begin(), out->end()), out->end());
    }
  } else {
    std::vector<int> order = all;
    std::sort(order.begin(), order.end(), [&](int a, int b) { return scene.views[a].name < scene.views[b].name; });
    for (std::size_t k = 0; k < order.size(); ++k)
      (opts.test_every > 0 && k % static_cast<std::size_t>(opts.test_every) == 0 ? scene.test : scene.train)
          .push_back(order[k]);
    std::sort(scene.train.begin(), scene.train.end());
    std::sort(scene.test.begin(), scene.test.end());
  }
  if (scene.train.empty()) throw InputError(file, "frames", "no train view left after the split");
  // nerfstudio's transforms.json says nothing of a background: the user's, else white
  // when the images have alpha (settleBackground), else none.
  BackgroundRule rule;
  rule.said = opts.background;
  settleBackground(scene, rule);

  // The initial points: ply_file_path (ns-process-data's sparse_pc.ply).
  if (const json* ply = jsonFind(j, "ply_file_path", file, "")) {
    const fs::path p = root / jsonString(*ply, file, "ply_file_path");
    if (!fs::exists(p)) throw InputError(file, "ply_file_path", "'" + p.string() + "' does not exist");
    for (const PlyPoint& q : readPointsPly(p.string())) scene.points.push_back({q.xyz, q.rgb});
  }
  scene.finalize();
  moveToOwnFrame(scene);
  return scene;
}

}  // namespace saresgs
