#include "geometry/lifting/sa_points.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>

#include "geometry/error.h"

namespace saresgs {

namespace {

using Clock = std::chrono::steady_clock;

double elapsedSeconds(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

void checkImage(const ImageF& img, const Camera& cam, const std::string& what) {
  if (img.width != cam.K.width || img.height != cam.K.height || img.channels < 1 ||
      img.data.size() != static_cast<std::size_t>(img.width) * img.height * img.channels)
    throw InputError("lifting", what,
                     "expected a " + std::to_string(cam.K.width) + "x" + std::to_string(cam.K.height) + " image, got " +
                         std::to_string(img.width) + "x" + std::to_string(img.height) + "x" +
                         std::to_string(img.channels));
}

Eigen::Vector3f colourAt(const ImageF& img, const Eigen::Vector2d& x) {
  const int i = std::clamp(static_cast<int>(std::floor(x.x())), 0, img.width - 1);
  const int j = std::clamp(static_cast<int>(std::floor(x.y())), 0, img.height - 1);
  Eigen::Vector3f c;
  for (int k = 0; k < 3; ++k) {
    const float v = img.at(i, j, std::min(k, img.channels - 1));
    c[k] = std::isfinite(v) ? v : 0.0f;
  }
  return c;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t h = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + h, v.end());
  if (v.size() % 2) return v[h];
  return 0.5 * (v[h] + *std::max_element(v.begin(), v.begin() + h));
}

}  // namespace

std::string matchesPath(const std::string& pattern, int view, int extrapolation) {
  std::string out = pattern;
  auto replaceAll = [&](const std::string& key, const std::string& value) {
    for (std::size_t p = out.find(key); p != std::string::npos; p = out.find(key, p + value.size()))
      out.replace(p, key.size(), value);
  };
  replaceAll("{view}", std::to_string(view));
  replaceAll("{extrapolation}", std::to_string(extrapolation));
  return out;
}

LiftingModule matchesModule(std::string path_pattern, const MatchesFileOptions& opts) {
  LiftingModule m;
  m.name = "matches";
  // The matcher ran elsewhere on the render; nothing to render here.
  m.needs_render = false;
  m.correspond = [pattern = std::move(path_pattern), opts](const LiftingPair& pair) {
    CorrespondenceSet s;
    s.matches = readMatches(matchesPath(pattern, pair.view, pair.extrapolation), opts);
    s.candidates = s.matches.size();
    return s;
  };
  return m;
}

CorrespondenceSet depthCorrespondences(const Camera& real, const ImageF& depth, const Camera& other) {
  checkImage(depth, real, "depth map");
  CorrespondenceSet out;
  out.candidates = static_cast<std::size_t>(depth.width) * depth.height;
  for (int j = 0; j < depth.height; ++j)
    for (int i = 0; i < depth.width; ++i) {
      const float z = depth.at(i, j);
      if (!(z > 0.0f) || !std::isfinite(z)) continue;
      const Eigen::Vector2d uv(i + 0.5, j + 0.5);
      const auto p = other.project(real.unproject(uv, z));
      if (p && p->allFinite()) out.matches.push_back({uv, *p});
    }
  return out;
}

LiftingModule depthModule(DepthRenderer depth_of) {
  LiftingModule m;
  m.name = "depth";
  m.needs_render = false;
  m.correspond = [depth_of = std::move(depth_of)](const LiftingPair& pair) {
    return depthCorrespondences(pair.real, depth_of(pair.real), pair.extrapolated);
  };
  return m;
}

void LiftingReport::add(const LiftingReport& o) {
  extrapolated_views += o.extrapolated_views;
  candidates += o.candidates;
  correspondences += o.correspondences;
  subsampled += o.subsampled;
  kept += o.kept;
  for (int r = 0; r < kRejectionCount; ++r) rejected[r] += o.rejected[r];
  seconds_render += o.seconds_render;
  seconds_correspondence += o.seconds_correspondence;
  seconds_triangulation += o.seconds_triangulation;
}

nlohmann::json LiftingReport::toJson() const {
  nlohmann::json rej = nlohmann::json::object();
  for (int r = 1; r < kRejectionCount; ++r) rej[rejectionName(static_cast<Rejection>(r))] = rejected[r];
  return {{"module", module},
          {"view", view},
          {"extrapolated_views", extrapolated_views},
          {"candidates", candidates},
          {"correspondences", correspondences},
          {"subsampled", subsampled},
          {"kept", kept},
          {"rejected", rej},
          {"median_reprojection_px", median_reprojection_px},
          {"seconds",
           {{"render", seconds_render},
            {"correspondence", seconds_correspondence},
            {"triangulation", seconds_triangulation}}}};
}

LiftingResult liftView(const Camera& real, const ImageF& real_image, double extent, const ViewRenderer& render,
                       const LiftingModule& module, const LiftingOptions& opts, int view) {
  if (!(extent > 0) || !std::isfinite(extent))
    throw InputError("lifting", "extent", "expected a positive finite scene extent, got " + std::to_string(extent));
  if (opts.stride < 1)
    throw InputError("lifting options", "stride", "expected >= 1, got " + std::to_string(opts.stride));
  if (!module.correspond) throw InputError("lifting", "module", "module '" + module.name + "' has no function");
  if (module.needs_render && !render)
    throw InputError("lifting", "renderer", "module '" + module.name + "' needs a renderer");
  checkImage(real_image, real, "real image");

  TriangulationOptions tri;
  tri.max_reprojection_px = opts.max_reprojection_px;
  tri.min_ray_angle_deg = opts.min_ray_angle_deg;
  tri.near = opts.near_fraction * extent;
  tri.border_px = opts.border_px;

  LiftingResult result;
  LiftingReport& rep = result.report;
  rep.module = module.name;
  rep.view = view;
  std::vector<double> errors;
  const std::vector<Camera> cams = extrapolatedCameras(real, extent, opts.extrapolation);
  for (std::size_t k = 0; k < cams.size(); ++k) {
    const Camera& cam = cams[k];
    ImageF rendered;
    if (module.needs_render) {
      const auto t0 = Clock::now();
      rendered = render(cam);
      rep.seconds_render += elapsedSeconds(t0);
      checkImage(rendered, cam, "extrapolated render");
    }

    auto t0 = Clock::now();
    const LiftingPair pair{real, real_image, cam, rendered, view, static_cast<int>(k), opts.stride};
    const CorrespondenceSet set = module.correspond(pair);
    const std::vector<Correspondence> sub = subsampleByStride(set.matches, opts.stride, real.K.width, real.K.height);
    rep.seconds_correspondence += elapsedSeconds(t0);

    t0 = Clock::now();
    const std::vector<TriangulatedPoint> tp = triangulateAll(real, cam, sub, tri);
    for (std::size_t i = 0; i < tp.size(); ++i) {
      if (!tp[i].kept()) {
        ++rep.rejected[static_cast<int>(tp[i].rejection)];
        continue;
      }
      result.points.push_back(
          {tp[i].X, colourAt(real_image, sub[i].x0), sub[i].x0, static_cast<float>(tp[i].reprojection_px)});
      errors.push_back(tp[i].reprojection_px);
    }
    rep.seconds_triangulation += elapsedSeconds(t0);

    ++rep.extrapolated_views;
    rep.candidates += set.candidates;
    rep.correspondences += set.matches.size();
    rep.subsampled += sub.size();
  }
  rep.kept = result.points.size();
  rep.median_reprojection_px = median(std::move(errors));
  return result;
}

std::vector<Eigen::Vector3d> positions(std::span<const SAPoint> points) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(points.size());
  for (const auto& p : points) out.push_back(p.position);
  return out;
}

}  // namespace saresgs
