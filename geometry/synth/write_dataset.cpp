#include "geometry/synth/write_dataset.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <unistd.h>

#include "geometry/image/contact_sheet.h"
#include "geometry/io/atomic_file.h"
#include "geometry/io/pfm.h"
#include "geometry/io/point_ply.h"
#include "geometry/scene/colmap_convert.h"
#include "geometry/synth/colmap_sfm.h"

namespace saresgs {

namespace fs = std::filesystem;

namespace {

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Replaces `dst` by the finished folder `src` so that a reader never sees a half-written
// dataset: the old one is moved aside first and removed last.
void replaceFolder(const fs::path& src, const fs::path& dst) {
  fs::path old;
  if (fs::exists(dst)) {
    old = dst.string() + ".old-" + std::to_string(::getpid());
    fs::rename(dst, old);
  }
  fs::rename(src, dst);
  if (!old.empty()) fs::remove_all(old);
}

// Blender's camera-to-world matrix: OpenGL axes (y up, z backward) are OpenCV's with y and
// z flipped.
nlohmann::json openGlTransform(const Camera& cam) {
  Eigen::Matrix4d c2w = Eigen::Matrix4d::Identity();
  c2w.topLeftCorner<3, 3>() = cam.R.transpose() * Eigen::Vector3d(1, -1, -1).asDiagonal();
  c2w.topRightCorner<3, 1>() = cam.center();
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({c2w(r, 0), c2w(r, 1), c2w(r, 2), c2w(r, 3)});
  return rows;
}

// transforms_<part>.json for the views `which`, NeRF-synthetic's keys; cameras that
// camera_angle_x alone cannot describe (fx != fy, off-centre principal point) also get
// Instant-NGP's fl_x, fl_y, cx, cy, w, h.
std::string transformsJson(const SyntheticScene& scene, const std::vector<int>& which, const std::string& part) {
  nlohmann::json j;
  const Intrinsics& K = scene.cameras.front().K;
  j["camera_angle_x"] = K.fovX();
  const bool simple = K.fx == K.fy && K.cx == 0.5 * K.width && K.cy == 0.5 * K.height;
  for (const Camera& c : scene.cameras)
    if (!(c.K == K)) throw std::invalid_argument("blender format: every view must share one camera");
  if (!simple) j.update({{"fl_x", K.fx}, {"fl_y", K.fy}, {"cx", K.cx}, {"cy", K.cy}, {"w", K.width}, {"h", K.height}});
  j["frames"] = nlohmann::json::array();
  for (int i : which)
    j["frames"].push_back(
        {{"file_path", "./" + part + "/" + fs::path(scene.names[static_cast<std::size_t>(i)]).stem().string()},
         {"rotation", 0.0},
         {"transform_matrix", openGlTransform(scene.cameras[static_cast<std::size_t>(i)])}});
  return j.dump(2) + "\n";
}

}  // namespace

ColmapModel colmapModelOf(const SyntheticScene& scene) {
  ColmapModel model;
  std::vector<Intrinsics> distinct;
  for (size_t i = 0; i < scene.cameras.size(); ++i) {
    const Camera& cam = scene.cameras[i];
    auto it = std::find_if(distinct.begin(), distinct.end(), [&](const Intrinsics& K) { return K == cam.K; });
    std::uint32_t cam_id;
    if (it == distinct.end()) {
      distinct.push_back(cam.K);
      cam_id = static_cast<std::uint32_t>(distinct.size());
      model.cameras.emplace(cam_id, colmapFromIntrinsics(cam.K, cam_id));
    } else {
      cam_id = static_cast<std::uint32_t>(it - distinct.begin() + 1);
    }
    ColmapImage im;
    im.id = static_cast<std::uint32_t>(i + 1);
    im.q = cam.quaternion();
    im.t = cam.t;
    im.camera_id = cam_id;
    im.name = scene.names[i];
    model.images.emplace(im.id, std::move(im));
  }
  return model;
}

WriteDatasetReport writeSyntheticDataset(const SyntheticScene& scene, const std::string& out,
                                         const WriteDatasetOptions& opts) {
  const bool blender = opts.format == "blender";
  if (!blender && opts.format != "colmap")
    throw std::invalid_argument("--format: expected colmap or blender, got '" + opts.format + "'");
  if (blender && opts.sfm == "colmap")
    throw std::invalid_argument("--sfm colmap needs --format colmap (COLMAP reads the images/ folder)");
  if (scene.cameras.empty()) throw std::invalid_argument("the scene has no views");
  const fs::path dst(out);
  const fs::path tmp = dst.string() + ".partial-" + std::to_string(::getpid());
  fs::remove_all(tmp);
  fs::create_directories(tmp / "depth");
  WriteDatasetReport report;
  report.views = static_cast<int>(scene.cameras.size());
  auto progress = [&](const std::string& stage, int done, int total) {
    if (opts.progress) opts.progress(stage, done, total);
  };
  std::vector<bool> is_test(scene.cameras.size(), false);
  for (int i : scene.test) is_test[static_cast<std::size_t>(i)] = true;

  // Renders, one view at a time (each render is parallel inside); thumbnails kept for
  // the contact sheet.
  const auto t_render = std::chrono::steady_clock::now();
  std::vector<double> view_ms;
  std::vector<Image8> images(scene.cameras.size());
  const float background[3] = {scene.background.x(), scene.background.y(), scene.background.z()};
  for (size_t i = 0; i < scene.cameras.size(); ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    fs::path image_file = tmp / "images" / scene.names[i];
    if (!blender) {
      images[i] = toByte(scene.render(scene.cameras[i], opts.render));
      view_ms.push_back(1e3 * secondsSince(t0));
      fs::create_directories(image_file.parent_path());
      writeImage(image_file.string(), images[i]);
    } else {
      // RGBA: the object's coverage as alpha; a room is opaque everywhere.
      Image8 rgba;
      if (scene.enclosed) {
        const Image8 rgb = toByte(scene.render(scene.cameras[i], opts.render));
        rgba = Image8(rgb.width, rgb.height, 4, 255);
        for (std::size_t p = 0; p < static_cast<std::size_t>(rgb.width) * rgb.height; ++p)
          for (int c = 0; c < 3; ++c) rgba.data[4 * p + c] = rgb.data[3 * p + c];
      } else {
        rgba = toByte(scene.renderRgba(scene.cameras[i], opts.render));
      }
      view_ms.push_back(1e3 * secondsSince(t0));
      images[i] = compositeOnBackground(rgba, background);
      image_file = tmp / (is_test[i] ? "test" : "train") / scene.names[i];
      fs::create_directories(image_file.parent_path());
      writeImage(image_file.string(), rgba);
    }
    writePfm((tmp / "depth" / (fs::path(scene.names[i]).stem().string() + ".pfm")).string(),
             scene.renderDepth(scene.cameras[i]));
    progress("render", static_cast<int>(i + 1), report.views);
  }
  report.render_seconds = secondsSince(t_render);
  std::nth_element(view_ms.begin(), view_ms.begin() + view_ms.size() / 2, view_ms.end());
  report.median_view_ms = view_ms.empty() ? 0 : view_ms[view_ms.size() / 2];

  const auto t_sfm = std::chrono::steady_clock::now();
  ColmapModel model = colmapModelOf(scene);
  if (opts.sfm == "simulated") {
    simulateSfm(scene, model, opts.simulated);
    progress("sfm (simulated)", 1, 1);
  } else if (opts.sfm == "colmap") {
    model = triangulateWithColmap(scene, tmp.string(), model);
  } else if (opts.sfm != "none") {
    throw std::invalid_argument("--sfm: expected simulated, colmap or none, got '" + opts.sfm + "'");
  }
  report.sfm_seconds = secondsSince(t_sfm);
  if (!blender) {
    writeColmapText((tmp / "sparse" / "0").string(), model);
  } else {
    writeFileAtomic((tmp / "transforms_train.json").string(), transformsJson(scene, scene.train, "train"));
    writeFileAtomic((tmp / "transforms_test.json").string(), transformsJson(scene, scene.test, "test"));
    if (opts.sfm != "none") {
      std::vector<PlyPoint> points;
      for (const auto& [id, p] : model.points) points.push_back({p.xyz, p.rgb});
      writePointsPly((tmp / "points3d.ply").string(), points);
    }
  }

  report.points = model.points.size();
  double track = 0, err = 0;
  std::vector<double> errors;
  for (const auto& [id, p] : model.points) {
    track += p.track.size();
    err += p.error;
    errors.push_back(p.error);
  }
  if (report.points) {
    report.mean_track_length = track / report.points;
    report.mean_reprojection_error = err / report.points;
    std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
    report.median_reprojection_error = errors[errors.size() / 2];
  }

  nlohmann::json manifest = scene.manifest;
  // The split by image name: the COLMAP loader honours it instead of its every-8th rule
  // (a Blender folder's transforms files are its split).
  nlohmann::json split = {{"train", nlohmann::json::array()}, {"test", nlohmann::json::array()}};
  for (int i : scene.train) split["train"].push_back(scene.names[i]);
  for (int i : scene.test) split["test"].push_back(scene.names[i]);
  if (!blender) manifest["split"] = split;
  manifest["format"] = opts.format;
  manifest["depth"] = {{"format", "pfm"}, {"convention", "z along the camera axis; 0 where a ray misses"}};
  manifest["render"] = {{"samples_per_pixel", opts.render.samples_per_pixel}, {"specular", opts.render.specular}};
  manifest["sfm"] = {{"source", opts.sfm},
                     {"points", report.points},
                     {"mean_track_length", report.mean_track_length},
                     {"mean_reprojection_error_px", report.mean_reprojection_error},
                     {"median_reprojection_error_px", report.median_reprojection_error}};
  writeFileAtomic((tmp / "manifest.json").string(), manifest.dump(2) + "\n");

  std::vector<ContactSheetItem> items;
  // At most 64 thumbnails, evenly spread over the views.
  const size_t n = images.size(), shown = std::min<size_t>(n, 64);
  for (size_t k = 0; k < shown; ++k) {
    const size_t i = k * n / shown;
    items.push_back({&images[i], std::to_string(i) + (is_test[i] ? " test" : ""), is_test[i]});
  }
  writeImage((tmp / "contact_sheet.png").string(), makeContactSheet(items, 8, 160));

  replaceFolder(tmp, dst);
  return report;
}

}  // namespace saresgs
