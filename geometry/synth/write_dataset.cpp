#include "geometry/synth/write_dataset.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <unistd.h>

#include "geometry/image/contact_sheet.h"
#include "geometry/io/atomic_file.h"
#include "geometry/io/pfm.h"
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

}  // namespace

ColmapModel colmapModelOf(const SyntheticScene& scene) {
  ColmapModel model;
  std::vector<Intrinsics> distinct;
  for (size_t i = 0; i < scene.cameras.size(); ++i) {
    const Camera& cam = scene.cameras[i];
    auto it = std::find_if(distinct.begin(), distinct.end(),
                           [&](const Intrinsics& K) { return K == cam.K; });
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
  const fs::path dst(out);
  const fs::path tmp = dst.string() + ".partial-" + std::to_string(::getpid());
  fs::remove_all(tmp);
  fs::create_directories(tmp / "images");
  fs::create_directories(tmp / "depth");
  WriteDatasetReport report;
  report.views = static_cast<int>(scene.cameras.size());
  auto progress = [&](const std::string& stage, int done, int total) {
    if (opts.progress) opts.progress(stage, done, total);
  };

  // Renders, one view at a time (each render is parallel inside); thumbnails kept for
  // the contact sheet.
  const auto t_render = std::chrono::steady_clock::now();
  std::vector<double> view_ms;
  std::vector<Image8> images(scene.cameras.size());
  for (size_t i = 0; i < scene.cameras.size(); ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    images[i] = toByte(scene.render(scene.cameras[i], opts.render));
    view_ms.push_back(1e3 * secondsSince(t0));
    writeImage((tmp / "images" / scene.names[i]).string(), images[i]);
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
  writeColmapText((tmp / "sparse" / "0").string(), model);

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
  // The split by image name: the loader honours it instead of its every-8th rule.
  nlohmann::json split = {{"train", nlohmann::json::array()}, {"test", nlohmann::json::array()}};
  for (int i : scene.train) split["train"].push_back(scene.names[i]);
  for (int i : scene.test) split["test"].push_back(scene.names[i]);
  manifest["split"] = split;
  manifest["depth"] = {{"format", "pfm"}, {"convention", "z along the camera axis; 0 where a ray misses"}};
  manifest["render"] = {{"samples_per_pixel", opts.render.samples_per_pixel},
                        {"specular", opts.render.specular}};
  manifest["sfm"] = {{"source", opts.sfm},
                     {"points", report.points},
                     {"mean_track_length", report.mean_track_length},
                     {"mean_reprojection_error_px", report.mean_reprojection_error},
                     {"median_reprojection_error_px", report.median_reprojection_error}};
  writeFileAtomic((tmp / "manifest.json").string(), manifest.dump(2) + "\n");

  std::vector<ContactSheetItem> items;
  const std::vector<bool> is_test = [&] {
    std::vector<bool> t(scene.cameras.size(), false);
    for (int i : scene.test) t[i] = true;
    return t;
  }();
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
