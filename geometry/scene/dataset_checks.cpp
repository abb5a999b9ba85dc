#include "geometry/scene/dataset_checks.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <tuple>

#include "geometry/error.h"

namespace saresgs {

namespace {

std::string num(double v) {
  std::ostringstream o;
  o.precision(4);
  o << v;
  return o.str();
}

// Points of the scene that project into the view (in front of it, inside the image);
// stops counting at `enough`.
std::size_t pointsSeen(const Scene& scene, const Camera& c, std::size_t enough) {
  std::size_t n = 0;
  for (const SparsePoint& p : scene.points) {
    const auto uv = c.project(p.xyz);
    if (uv && c.inImage(*uv) && ++n >= enough) break;
  }
  return n;
}

}  // namespace

std::vector<DatasetWarning> checkDataset(const Scene& scene, double near_plane) {
  std::vector<DatasetWarning> out;
  std::size_t blind_train = 0;
  std::vector<bool> is_train(scene.views.size(), false);
  for (int i : scene.train) is_train[static_cast<std::size_t>(i)] = true;
  for (std::size_t i = 0; i < scene.views.size(); ++i) {
    const SceneView& v = scene.views[i];
    const Intrinsics& K = v.camera.K;
    for (const auto& [field, f, side] : {std::tuple{"fx", K.fx, K.width}, std::tuple{"fy", K.fy, K.height}}) {
      const double fov = 2 * std::atan(0.5 * side / f) * 180 / std::numbers::pi;
      if (!(fov >= kMinFovDeg && fov <= kMaxFovDeg))
        out.push_back({v.name, field,
                       std::string(field) + " = " + num(f) + " px for " + std::to_string(side) +
                           " px gives a field of view of " + num(fov) + " degrees, outside the " + num(kMinFovDeg) +
                           ".." + num(kMaxFovDeg) +
                           " that lenses give: is the focal length in pixels of this image size?"});
    }
    for (const auto& [field, c, side] : {std::tuple{"cx", K.cx, K.width}, std::tuple{"cy", K.cy, K.height}})
      if (!(c >= 0 && c <= side))
        out.push_back({v.name, field,
                       std::string(field) + " = " + num(c) + " px lies outside the image (0.." + std::to_string(side) +
                           " px): the principal point is normally near the centre, " + num(0.5 * side)});
    if (!scene.points.empty() && pointsSeen(scene, v.camera, 1) == 0) {
      blind_train += is_train[i];
      out.push_back({v.name, "points",
                     "none of the " + std::to_string(scene.points.size()) +
                         " sparse points projects into this view: check its intrinsics and pose"});
    }
  }
  // The frame: where the train cameras are, and over how much they spread.
  if (scene.train.size() >= 2) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int i : scene.train) c += scene.views[static_cast<std::size_t>(i)].camera.center();
    c /= static_cast<double>(scene.train.size());
    double r = 0;
    for (int i : scene.train) r = std::max(r, (scene.views[static_cast<std::size_t>(i)].camera.center() - c).norm());
    // In world units: a scene in a frame of its own trains there, but writes world .ply files.
    const double d = scene.frame.toWorld(c).norm(), rw = r * scene.frame.scale;
    if (rw > 0 && d > 100 * rw)
      out.push_back({"(scene)", "frame",
                     "the train cameras are centred " + num(d) + " from the origin, " + num(d / rw) +
                         " times their spread (" + num(rw) + "): single-precision Gaussian means resolve only " +
                         num(d * 6e-8) + " there; " +
                         (scene.frame.identity()
                              ? std::string("recentre the model before training (COLMAP: model_transformer)")
                              : "saresgs trains in a frame of its own about the scene, but the .ply files it writes "
                                "hold world coordinates in single precision (3DGS's format), so they keep only that; "
                                "recentre the model for a finer file (COLMAP: model_transformer)")});
    if (r > 0 && r < 50 * near_plane)
      out.push_back({"(scene)", "scale",
                     "the train cameras spread over " + num(r) + ", under 50 times the renderer's near plane (" +
                         num(near_plane) +
                         "): Gaussians nearer than that to a camera are not drawn; scale the model up "
                         "before training (COLMAP: model_transformer)"});
  }
  if (!scene.points.empty() && !scene.train.empty() && blind_train == scene.train.size())
    throw InputError(
        scene.source, "intrinsics or poses",
        "none of the " + std::to_string(scene.points.size()) + " sparse points projects into any of the " +
            std::to_string(scene.train.size()) +
            " train views, so nothing can be trained; check the cameras' intrinsics (focal length, "
            "principal point) and poses" +
            (out.empty() ? std::string() : " (first: " + out.front().view + ": " + out.front().message + ")"));
  return out;
}

std::string formatWarnings(const std::vector<DatasetWarning>& warnings, std::size_t max_lines) {
  std::ostringstream o;
  for (std::size_t i = 0; i < warnings.size() && i < max_lines; ++i)
    o << "warning: " << warnings[i].view << ": " << warnings[i].field << ": " << warnings[i].message << "\n";
  if (warnings.size() > max_lines) o << "warning: ... and " << warnings.size() - max_lines << " more like these\n";
  return o.str();
}

}  // namespace saresgs
