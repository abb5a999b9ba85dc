#include "nbv/eval/coverage_report.h"

#include "geometry/error.h"
#include "geometry/synth/from_manifest.h"
#include "splat/rasterize.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <numeric>

#include "geometry/occupancy/occupancy_grid.h"
#include "nbv/eval/camera_plot.h"

namespace saresgs {

CoverageAnalysis analyzeCoverage(const Scene& scene, const std::vector<int>& views, const PrefilterConfig& config,
                                 const ViewRenderer& render, const DepthRenderer& depth) {
  CoverageAnalysis a;
  a.views = views;
  auto t0 = std::chrono::steady_clock::now();
  a.prefilter = makeCoveragePrefilter(scene, config);
  a.seconds_grid = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  SelectionSeconds t;
  a.prefilter->observe(views, render, depth, t);
  a.seconds_lifting = t.lifting;
  a.seconds_triangulation = t.triangulation;
  std::vector<int> cand;
  for (int v : scene.train)
    if (std::find(views.begin(), views.end(), v) == views.end()) cand.push_back(v);
  const std::vector<double> scores = cand.empty() ? std::vector<double>{} : a.prefilter->score(cand, t);
  a.seconds_scoring = t.prefilter;
  std::vector<std::size_t> order(cand.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
    return scores[x] != scores[y] ? scores[x] > scores[y] : cand[x] < cand[y];
  });
  const std::vector<int> kept = cand.empty() ? std::vector<int>{} : topFraction(scores, cand, config.keep_fraction);
  a.candidates.resize(cand.size());
  for (std::size_t r = 0; r < order.size(); ++r) {
    const std::size_t i = order[r];
    a.candidates[i] = {cand[i], scores[i], static_cast<int>(r) + 1,
                       std::find(kept.begin(), kept.end(), cand[i]) != kept.end()};
  }
  for (std::size_t r = 0; r < order.size(); ++r)
    if (a.candidates[order[r]].kept) a.top.push_back(cand[order[r]]);
  const OccupancyGrids& g = a.prefilter->grids();
  a.observed_fraction = g.observedFraction();
  a.scene_voxels = g.sceneCount();
  a.observed_voxels = g.observedSceneVoxels().size();
  a.lifting = a.prefilter->liftingReport();
  return a;
}

Image8 plotCoverage(const Scene& scene, const CoverageAnalysis& a, int size) {
  const OccupancyGrids& g = a.prefilter->grids();
  const Eigen::Vector3d up = meanCameraUp(scene);  // "above", as in the camera plot
  // Keep the room's walls upright on the page: x is the world axis closest to the plane.
  Eigen::Vector3d ax = up.unitOrthogonal();
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(k), p = e - e.dot(up) * up;
    if (p.norm() > 0.7) {
      ax = p.normalized();
      break;
    }
  }
  const Eigen::Vector3d ay = up.cross(ax);
  PlaneBounds b{ax, ay};
  const std::vector<Voxel> occ = g.sceneVoxels().voxels();
  for (const Voxel& v : occ) b.extend(g.voxelCenter(v));
  for (const auto& v : scene.views) b.extend(v.camera.center());
  const double span = b.span() * 1.08;
  const double cx = b.centerX(), cy = b.centerY(), scale = (size - 40) / span;
  const int top_margin = 30;
  cv::Mat img(size + top_margin, size, CV_8UC3, cv::Scalar(255, 255, 255));
  auto px = [&](const Eigen::Vector3d& p) {
    return cv::Point(size / 2 + static_cast<int>((p.dot(ax) - cx) * scale),
                     top_margin + size / 2 - static_cast<int>((p.dot(ay) - cy) * scale));
  };
  const int r = std::max(1, static_cast<int>(0.5 * g.voxelSize() * scale));
  // Occupied voxels first, observed ones over them (a column seen from above counts as
  // observed when any voxel in it is).
  for (const Voxel& v : occ) {
    const cv::Point p = px(g.voxelCenter(v));
    cv::rectangle(img, p - cv::Point(r, r), p + cv::Point(r, r), cv::Scalar(190, 190, 190), cv::FILLED);
  }
  for (const Voxel& v : g.observedSceneVoxels().voxels()) {
    const cv::Point p = px(g.voxelCenter(v));
    cv::rectangle(img, p - cv::Point(r, r), p + cv::Point(r, r), cv::Scalar(200, 120, 40), cv::FILLED);
  }
  const double reach = 0.08 * span;
  auto frustum = [&](int view, const cv::Scalar& colour, int thick) {
    const Camera& c = scene.views[static_cast<std::size_t>(view)].camera;
    const Eigen::Vector3d o = c.center();
    const double w = c.K.width, h = c.K.height;
    for (const auto& uv : {Eigen::Vector2d(0, h / 2), Eigen::Vector2d(w, h / 2)}) {
      Eigen::Vector3d d = c.rayDirection(uv);
      cv::line(img, px(o), px(o + reach * d / std::max(1e-9, d.dot(c.viewDirection()))), colour, thick, cv::LINE_AA);
    }
    cv::circle(img, px(o), thick + 2, colour, cv::FILLED, cv::LINE_AA);
  };
  for (const auto& c : a.candidates)
    if (!c.kept) frustum(c.view, cv::Scalar(180, 180, 180), 1);
  for (const auto& c : a.candidates)
    if (c.kept) frustum(c.view, cv::Scalar(40, 170, 40), 2);
  for (int v : a.views) frustum(v, cv::Scalar(30, 30, 220), 2);
  char title[200];
  std::snprintf(title, sizeof title,
                "from above: occupied (grey) %zu, observed (blue) %zu = %.1f %%; red: views, green: top %zu",
                a.scene_voxels, a.observed_voxels, 100 * a.observed_fraction, a.top.size());
  cv::putText(img, title, cv::Point(8, 20), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  Image8 out(size, size + top_margin, 3);
  cv::Mat rgb;
  cv::cvtColor(img, rgb, cv::COLOR_BGR2RGB);
  std::memcpy(out.data.data(), rgb.data, out.data.size());
  return out;
}

CoverageRenderers coverageRenderers(const Scene& scene, const std::string& dataset_path, const Gaussians* model,
                                    const std::string& model_name, const std::string& how_to_give_a_model) {
  CoverageRenderers r;
  if (model) {
    RasterSettings rs;
    rs.sh_degree = model->max_sh_degree;
    if (scene.background) rs.background = *scene.background;
    r.render = [model, rs](const Camera& c) { return rasterize(*model, c, rs).rgb; };
    r.depth = [model, rs](const Camera& c) { return rasterize(*model, c, rs).depth; };
    r.source = "model " + model_name;
    return r;
  }
  std::optional<SyntheticScene> rebuilt = rebuildSyntheticScene(dataset_path, scene);
  if (!rebuilt)
    throw InputError(dataset_path, "manifest.json",
                     "not a rebuildable synthetic scene: give a trained model (" + how_to_give_a_model +
                         ") to render extrapolated views");
  auto truth = std::make_shared<const SyntheticScene>(std::move(*rebuilt));
  r.render = [truth](const Camera& c) { return truth->render(c); };
  r.depth = [truth](const Camera& c) { return truth->renderDepth(c); };
  r.source = "ground-truth renders of the synthetic scene";
  return r;
}

}  // namespace saresgs
