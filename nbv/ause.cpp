#include "nbv/ause.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "splat/fisher.h"

namespace saresgs {

namespace {

// Mean of error over pixels order[k..n) for each removal fraction, via suffix sums.
std::vector<double> curve(const std::vector<double>& error, const std::vector<std::size_t>& order, int steps) {
  const std::size_t n = order.size();
  std::vector<double> suffix(n + 1, 0.0);
  for (std::size_t k = n; k-- > 0;) suffix[k] = suffix[k + 1] + error[order[k]];
  std::vector<double> out;
  for (int s = 0; s < steps; ++s) {
    const std::size_t removed = static_cast<std::size_t>(static_cast<double>(s) / steps * static_cast<double>(n));
    out.push_back(suffix[removed] / static_cast<double>(n - removed));
  }
  return out;
}

}  // namespace

std::optional<SparsificationCurves> sparsification(const std::vector<double>& error,
                                                   const std::vector<double>& uncertainty, int steps) {
  if (error.size() != uncertainty.size()) throw std::invalid_argument("sparsification: sizes differ");
  if (steps < 2) throw std::invalid_argument("sparsification: at least 2 steps");
  const std::size_t n = error.size();
  if (n < 100) return std::nullopt;
  const double total = std::accumulate(error.begin(), error.end(), 0.0);
  if (!(total > 0)) return std::nullopt;
  std::vector<std::size_t> by_u(n), by_e(n);
  std::iota(by_u.begin(), by_u.end(), 0);
  std::iota(by_e.begin(), by_e.end(), 0);
  // Most uncertain (largest error) first: those are removed first.
  std::stable_sort(by_u.begin(), by_u.end(),
                   [&](std::size_t a, std::size_t b) { return uncertainty[a] > uncertainty[b]; });
  std::stable_sort(by_e.begin(), by_e.end(), [&](std::size_t a, std::size_t b) { return error[a] > error[b]; });
  SparsificationCurves c;
  c.by_uncertainty = curve(error, by_u, steps);
  c.oracle = curve(error, by_e, steps);
  const double base = c.by_uncertainty[0];
  double area = 0;
  for (int s = 0; s < steps; ++s) {
    c.fraction.push_back(static_cast<double>(s) / steps);
    c.by_uncertainty[s] /= base;
    c.oracle[s] /= base;
    area += c.by_uncertainty[s] - c.oracle[s];
  }
  c.ause = area / steps;
  return c;
}

std::optional<double> depthAuse(const Trainer& t, const std::vector<int>& train_views, const std::vector<int>& views,
                                double lambda) {
  const Scene& scene = t.scene();
  bool any = false;
  for (int v : views) any = any || scene.hasDepth(v);
  if (!any) return std::nullopt;
  const RasterSettings s = t.rasterSettings();
  Gaussians H = t.gaussians().zerosLike();
  for (int v : train_views) addViewInformation(t.gaussians(), scene.views[static_cast<std::size_t>(v)].camera, s, H);
  const Gaussians unc = withScalarColor(t.gaussians(), gaussianGeometryVariance(H, lambda));
  RasterSettings us = s;
  us.sh_degree = 0;
  us.background = {0, 0, 0};
  double sum = 0;
  int n = 0;
  for (int v : views) {
    if (!scene.hasDepth(v)) continue;
    const Camera& cam = scene.views[static_cast<std::size_t>(v)].camera;
    const ImageF gt = scene.depth(v);
    const RenderResult r = t.render(cam);
    const RenderResult u = rasterize(unc, cam, us);
    std::vector<double> err, un;
    for (std::size_t p = 0; p < gt.data.size(); ++p) {
      if (!(gt.data[p] > 0)) continue;
      err.push_back(std::abs(static_cast<double>(r.depth.data[p]) - gt.data[p]));
      un.push_back(u.rgb.data[3 * p]);
    }
    if (const auto c = sparsification(err, un)) {
      sum += c->ause;
      ++n;
    }
  }
  if (n == 0) return std::nullopt;
  return sum / n;
}

}  // namespace saresgs
