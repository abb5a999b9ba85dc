#include "report/run_page.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <numeric>
#include <optional>

#include "geometry/error.h"
#include "geometry/image/image.h"
#include "geometry/io/atomic_file.h"
#include "geometry/io/json_file.h"
#include "geometry/scene/dataset_checks.h"
#include "nbv/run_report.h"
#include "report/html_page.h"
#include "splat/model_frame.h"
#include "splat/model_ops.h"
#include "splat/ply.h"
#include "splat/rasterize.h"
#include "splat/splat_file.h"

namespace saresgs {

namespace fs = std::filesystem;

namespace {

// The error image's full scale: mean |render - truth| over RGB at which it saturates.
constexpr float kErrorScale = 0.25f;
// Pictures wider than this are shown (and stored) at this width.
constexpr int kMaxPictureWidth = 512;

// A perceptual dark-to-bright ramp (black, purple, red, orange, pale yellow) for errors.
std::array<std::uint8_t, 3> ramp(float u) {
  static constexpr float kStops[5][3] = {{0, 0, 4}, {87, 16, 110}, {188, 55, 84}, {249, 142, 9}, {252, 255, 164}};
  u = std::clamp(u, 0.0f, 1.0f) * 4.0f;
  const int k = std::min(3, static_cast<int>(u));
  const float f = u - static_cast<float>(k);
  std::array<std::uint8_t, 3> c{};
  for (int i = 0; i < 3; ++i)
    c[static_cast<std::size_t>(i)] =
        static_cast<std::uint8_t>(std::lround(kStops[k][i] + f * (kStops[k + 1][i] - kStops[k][i])));
  return c;
}

Image8 errorImage(const ImageF& render, const Image8& truth) {
  Image8 out(truth.width, truth.height, 3);
  for (int y = 0; y < truth.height; ++y)
    for (int x = 0; x < truth.width; ++x) {
      float e = 0;
      for (int c = 0; c < 3; ++c) e += std::abs(render.at(x, y, c) - truth.at(x, y, c) / 255.0f);
      const auto rgb = ramp(e / 3.0f / kErrorScale);
      for (int c = 0; c < 3; ++c) out.at(x, y, c) = rgb[static_cast<std::size_t>(c)];
    }
  return out;
}

Image8 forDisplay(const Image8& img) {
  if (img.width <= kMaxPictureWidth) return img;
  const int h =
      std::max(1, static_cast<int>(std::lround(static_cast<double>(img.height) * kMaxPictureWidth / img.width)));
  return resizeImage(img, kMaxPictureWidth, h);
}

std::string jpegUrl(const Image8& img) {
  const std::vector<std::uint8_t> b = encodeImage(forDisplay(img), ".jpg", 88);
  return dataUrl("image/jpeg", std::string_view(reinterpret_cast<const char*>(b.data()), b.size()));
}

nlohmann::json cameraJson(const Camera& c, const std::string& name, const std::string& role, std::optional<int> order,
                          bool train) {
  nlohmann::json R = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) R.push_back({c.R(r, 0), c.R(r, 1), c.R(r, 2)});
  nlohmann::json j = {{"name", name},
                      {"role", role},
                      {"width", c.K.width},
                      {"height", c.K.height},
                      {"fx", c.K.fx},
                      {"fy", c.K.fy},
                      {"cx", c.K.cx},
                      {"cy", c.K.cy},
                      {"R", R},
                      {"t", {c.t.x(), c.t.y(), c.t.z()}},
                      {"train", train}};
  j["order"] = order ? nlohmann::json(*order) : nlohmann::json();
  return j;
}

struct Model {
  Gaussians g;
  std::string file, which;
};

// The model the page shows: the final fit's, else the loop's; what is missing said.
std::optional<Model> loadModel(const fs::path& dir, const RunReport& rep, std::vector<std::string>& missing) {
  std::vector<std::pair<std::string, std::string>> order;
  if (rep.final_fit) order.emplace_back("final_fit.ply", "final fit");
  order.emplace_back("point_cloud.ply", "in-loop model");
  for (const auto& [file, which] : order) {
    const fs::path p = dir / file;
    if (!fs::exists(p)) {
      missing.push_back(
          file + " is missing" +
          (file == "final_fit.ply" ? std::string(": the page shows the in-loop model instead") : std::string()));
      continue;
    }
    try {
      return Model{readGaussiansPly(p.string()), file, which};
    } catch (const std::exception& e) {
      missing.push_back(file + " could not be read: " + e.what());
    }
  }
  missing.push_back("no model could be read: no 3D view and no renders");
  return std::nullopt;
}

// The dataset as the run loaded it: its path from results.json (or the caller's), the
// background the run used, and the resolution of its cameras.json (a run with --downscale).
// A run inside a grid (GRID/runs/SCENE__METHOD__VARIANT__sSEED): the other finished jobs of
// the same scene and seed, as curve series {name, points: [[views, progress PSNR], ...],
// final: final-fit PSNR or null}.
nlohmann::json gridSiblingCurves(const fs::path& dir) {
  nlohmann::json out = nlohmann::json::array();
  const fs::path runs = fs::absolute(dir).lexically_normal().parent_path();
  if (runs.filename() != "runs") return out;
  const std::string me = fs::absolute(dir).lexically_normal().filename().string();
  const std::vector<std::string> mine = jobNameParts(me);
  if (mine.size() < 4) return out;
  std::vector<fs::path> sibs;
  for (const auto& e : fs::directory_iterator(runs))
    if (e.is_directory() && e.path().filename().string() != me) sibs.push_back(e.path());
  std::sort(sibs.begin(), sibs.end());
  for (const fs::path& p : sibs) {
    const std::vector<std::string> theirs = jobNameParts(p.filename().string());
    if (theirs.size() < 4 || theirs[0] != mine[0] || theirs[3] != mine[3] || !fs::exists(p / "results.json")) continue;
    try {
      const nlohmann::json r = readJsonFile((p / "results.json").string());
      nlohmann::json pts = nlohmann::json::array();
      for (const auto& st : r.at("steps")) pts.push_back({st.at("views_before"), st.at("progress_psnr")});
      const std::string label = theirs[2] == "default" ? theirs[1] : theirs[1] + " " + theirs[2];
      nlohmann::json final_psnr;
      if (r.contains("final_fit") && r["final_fit"].is_object())
        final_psnr = r["final_fit"].value("psnr", nlohmann::json());
      out.push_back({{"name", label}, {"job", p.filename().string()}, {"points", pts}, {"final", final_psnr}});
    } catch (const std::exception&) {
      // a sibling that cannot be read is left out of the curve; the grid page lists it
    }
  }
  return out;
}

std::optional<Scene> loadRunDataset(const fs::path& dir, const nlohmann::json& results, const std::string& path,
                                    std::vector<std::string>& missing) {
  DatasetOptions dopt;
  if (const auto* bg = results.is_object() && results.contains("background") ? &results["background"] : nullptr;
      bg && bg->is_object() && bg->contains("color") && (*bg)["color"].is_array() && (*bg)["color"].size() == 3) {
    BackgroundChoice b;
    for (int c = 0; c < 3; ++c)
      b.color[static_cast<std::size_t>(c)] = (*bg)["color"][static_cast<std::size_t>(c)].get<float>();
    b.random = bg->value("random", false);
    dopt.background = b;
  }
  try {
    Scene s = loadDataset(path, dopt);
    const fs::path cams = dir / "cameras.json";
    if (fs::exists(cams) && !s.views.empty()) {
      const nlohmann::json cj = readJsonFile(cams.string());
      if (cj.is_array() && !cj.empty() && cj[0].is_object() && cj[0].contains("width")) {
        const int w = cj[0]["width"].get<int>();
        const int full = s.views[0].camera.K.width;
        if (w > 0 && w < full) {
          dopt.load.downscale = static_cast<int>(std::lround(static_cast<double>(full) / w));
          s = loadDataset(path, dopt);
        }
      }
    }
    return s;
  } catch (const std::exception& e) {
    missing.push_back("the dataset " + path + " could not be read (" + e.what() +
                      "): no cameras, ground truth or renders; pass --dataset to point at it");
    return std::nullopt;
  }
}

}  // namespace

RunPageResult writeRunPage(const std::string& run_dir, const Scene* given, const RunPageOptions& o) {
  const fs::path dir(run_dir);
  if (!fs::is_directory(dir))
    throw InputError(run_dir, "folder", "not a folder: expected the --out folder of `saresgs active`");
  const fs::path results_path = dir / "results.json";
  if (!fs::exists(results_path)) {
    if (fs::exists(dir / "checkpoint.json"))
      throw InputError(results_path.string(), "file",
                       "missing: the run was interrupted before its end (checkpoint.json is there); finish it with "
                       "`saresgs active ... --resume` and report again");
    throw InputError(results_path.string(), "file",
                     "missing: expected the results.json `saresgs active` writes at its end");
  }
  const nlohmann::json results = readJsonFile(results_path.string());
  const RunReport rep = runReportFromJson(results, results_path.string());

  RunPageResult res;
  res.path = o.out.empty() ? (dir / "report.html").string() : o.out;
  std::vector<std::string>& missing = res.missing;
  nlohmann::json notes = nlohmann::json::array();
  if (!rep.final_fit)
    notes.push_back(
        "This run made no final fit (--final-iterations 0): the model shown is the one trained in the loop.");

  std::optional<Model> model = loadModel(dir, rep, missing);

  std::optional<Scene> own;
  const Scene* scene = given;
  const std::string dataset_path = o.dataset.empty() ? rep.dataset : o.dataset;
  if (!scene) {
    own = loadRunDataset(dir, results, dataset_path, missing);
    if (own) scene = &*own;
  }

  // Cameras, in world coordinates, with their role in the run.
  std::map<std::string, int> chosen_order;
  for (std::size_t k = 0; k < rep.selected_views.size(); ++k)
    chosen_order[rep.selected_views[k]] = static_cast<int>(k + 1);
  std::map<std::string, bool> initial, test;
  for (const std::string& n : rep.initial_views) initial[n] = true;
  for (const ViewReport& v : rep.views) test[v.name] = true;
  nlohmann::json cameras = nlohmann::json::array();
  std::map<std::string, int> index_of;
  nlohmann::json warnings = nlohmann::json::array();
  if (scene) {
    std::vector<bool> is_train(scene->views.size(), false);
    for (const int i : scene->train) is_train[static_cast<std::size_t>(i)] = true;
    for (std::size_t i = 0; i < scene->views.size(); ++i) {
      const SceneView& v = scene->views[i];
      index_of[v.name] = static_cast<int>(i);
      const Camera w = scene->frame.toWorld(v.camera);
      std::string role = "candidate";
      std::optional<int> order;
      if (initial.count(v.name))
        role = "initial";
      else if (auto it = chosen_order.find(v.name); it != chosen_order.end())
        role = "chosen", order = it->second;
      else if (test.count(v.name))
        role = "test";
      cameras.push_back(cameraJson(w, v.name, role, order, is_train[i]));
    }
  }
  // What the run printed before it started (results.json's "warnings", written by
  // `saresgs active`), else the dataset's checks made again here.
  std::string warnings_from = "the run";
  if (results.contains("warnings") && results["warnings"].is_array()) {
    for (const auto& w : results["warnings"])
      if (w.is_string()) warnings.push_back(w);
  } else if (scene) {
    warnings_from = "the dataset's checks, made again for this page";
    for (const DatasetWarning& w : checkDataset(*scene))
      warnings.push_back((w.view.empty() ? std::string() : w.view + ": ") + w.field + ": " + w.message);
    if (const std::string b = backgroundWarning(*scene); !b.empty()) warnings.push_back(b);
  } else {
    warnings_from = "nothing (no dataset read)";
  }

  // The test views with the model shown: its own numbers from results.json, its render,
  // the error, the depth error and the distance to the nearest held view.
  const bool shows_final = model && model->file == "final_fit.ply";
  const std::vector<ViewReport>& shown_views = shows_final ? rep.final_fit->views : rep.views;
  std::map<std::string, const ViewReport*> loop_view;
  for (const ViewReport& v : rep.views) loop_view[v.name] = &v;
  std::vector<Eigen::Vector3d> held;
  if (scene)
    for (const int i : rep.selected_view_indices)
      if (i >= 0 && static_cast<std::size_t>(i) < scene->views.size())
        held.push_back(scene->frame.toWorld(scene->views[static_cast<std::size_t>(i)].camera).center());
  std::optional<Gaussians> internal;
  if (model && scene) internal = gaussiansFromWorld(model->g, scene->frame);
  nlohmann::json views = nlohmann::json::array();
  bool rendered_any = false;
  for (const ViewReport& v : shown_views) {
    nlohmann::json j = {{"name", v.name}, {"psnr", v.psnr}, {"ssim", v.ssim}};
    if (auto it = loop_view.find(v.name); it != loop_view.end() && shows_final) j["loop_psnr"] = it->second->psnr;
    const auto at = index_of.find(v.name);
    if (scene && at != index_of.end()) {
      const int i = at->second;
      const Camera w = scene->frame.toWorld(scene->views[static_cast<std::size_t>(i)].camera);
      double nearest = std::numeric_limits<double>::infinity();
      for (const Eigen::Vector3d& c : held) nearest = std::min(nearest, (c - w.center()).norm());
      if (std::isfinite(nearest)) j["nearest_held"] = nearest;
      try {
        const Image8& truth = scene->image(i);
        j["truth"] = jpegUrl(truth);
        if (internal) {
          RasterSettings s;
          s.sh_degree = internal->max_sh_degree;
          if (scene->background) s.background = *scene->background;
          s.execution.threads = o.threads;
          const RenderResult r = rasterize(*internal, scene->views[static_cast<std::size_t>(i)].camera, s);
          j["render"] = jpegUrl(toByte(r.rgb));
          j["error"] = jpegUrl(errorImage(r.rgb, truth));
          rendered_any = true;
          if (scene->hasDepth(i)) {
            const ImageF gt = scene->depth(i);
            double sum = 0;
            std::size_t n = 0;
            for (int y = 0; y < gt.height && y < r.depth.height; ++y)
              for (int x = 0; x < gt.width && x < r.depth.width; ++x) {
                const float d = gt.at(x, y);
                if (!(d > 0) || !std::isfinite(d)) continue;
                sum += std::abs(static_cast<double>(r.depth.at(x, y)) - d);
                ++n;
              }
            if (n) j["depth_error"] = sum / static_cast<double>(n) * scene->frame.scale;
          }
        }
      } catch (const std::exception& e) {
        j["problem"] = e.what();
      }
    } else if (scene) {
      j["problem"] = "not a view of the dataset read";
    }
    views.push_back(std::move(j));
  }
  if (scene && model && !rendered_any && !shown_views.empty()) missing.push_back("no test view could be rendered");

  // The model for the viewer, as its .ply when it fits the budget.
  nlohmann::json model_info;
  std::string model_bytes;
  if (model) {
    model_info = {{"file", model->file},
                  {"which", model->which},
                  {"gaussians", model->g.size()},
                  {"sh_degree", model->g.max_sh_degree}};
    std::string ply = readFile((dir / model->file).string());
    if (ply.size() <= o.model_budget_bytes) {
      model_bytes = std::move(ply);
      model_info["format"] = "ply";
      model_info["note"] = "the model's own .ply, exact";
    } else {
      Gaussians g = model->g;
      std::size_t keep = std::min(g.size(), o.model_budget_bytes / kSplatRecordBytes);
      std::string note =
          "the .ply (" + std::to_string(ply.size() >> 20) +
          " MB) is larger than the page's budget: shown as a .splat (degree-0 colour, 8-bit colour, opacity "
          "and rotation)";
      if (keep < g.size()) {
        // the most opaque Gaussians, in the model's order
        std::vector<int> idx(g.size());
        std::iota(idx.begin(), idx.end(), 0);
        std::stable_sort(idx.begin(), idx.end(), [&](int a, int b) { return g.opacities[a] > g.opacities[b]; });
        idx.resize(keep);
        std::sort(idx.begin(), idx.end());
        g = gatherGaussians(g, idx);
        note +=
            ", and only its " + std::to_string(keep) + " most opaque Gaussians of " + std::to_string(model->g.size());
      }
      model_bytes = splatFileBytes(g);
      model_info["format"] = "splat";
      model_info["shown_gaussians"] = g.size();
      model_info["note"] = note;
    }
    model_info["bytes"] = model_bytes.size();
  }

  const ViewerScript viewer = findViewerScript(o.viewer_script);
  res.viewer = !viewer.script.empty() && !model_bytes.empty();
  if (viewer.script.empty())
    missing.push_back("the 3D viewer's script is not installed (looked for " + viewer.path +
                      "): run `bash scripts/install_node_tools.sh`, then `saresgs report` again");

  nlohmann::json dataset = {{"path", dataset_path}, {"loaded", scene != nullptr}};
  if (scene) {
    dataset["views"] = scene->views.size();
    dataset["train"] = scene->train.size();
    dataset["test"] = scene->test.size();
    dataset["frame"] = toJson(scene->frame);
    dataset["background"] = scene->background ? nlohmann::json(*scene->background) : nlohmann::json();
    dataset["background_from"] = scene->background_from;
  }
  const std::string name = fs::path(rep.dataset).filename().string();
  nlohmann::json data = {{"kind", "run"},
                         {"title", rep.method + " on " + (name.empty() ? rep.dataset : name)},
                         {"run_dir", dir.string()},
                         {"results", results},
                         {"missing", missing},
                         {"notes", notes},
                         {"warnings", warnings},
                         {"warnings_from", warnings_from},
                         {"dataset", dataset},
                         {"model", model_info},
                         {"cameras", cameras},
                         {"views", views},
                         {"error_scale", kErrorScale},
                         {"baselines", gridSiblingCurves(dir)},
                         {"viewer", {{"present", !viewer.script.empty()}, {"path", viewer.path}}}};
  PageParts parts;
  parts.title = "saresgs report: " + data["title"].get<std::string>();
  parts.data = std::move(data);
  parts.model_base64 = base64Encode(model_bytes);
  parts.viewer_script = res.viewer ? viewer.script : std::string();
  const std::string html = pageHtml(parts);
  writeFileAtomic(res.path, html);
  res.bytes = html.size();
  return res;
}

std::vector<std::string> jobNameParts(const std::string& name) {
  std::vector<std::string> parts;
  for (std::size_t p = 0;;) {
    const std::size_t q = name.find("__", p);
    parts.push_back(name.substr(p, q == std::string::npos ? std::string::npos : q - p));
    if (q == std::string::npos) break;
    p = q + 2;
  }
  return parts;
}

}  // namespace saresgs
