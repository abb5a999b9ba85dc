#include "nbv/selectors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

#include "splat/fisher.h"

namespace saresgs {

int selectRandom(const std::vector<int>& candidates, std::mt19937_64& rng) {
  if (candidates.empty()) throw std::invalid_argument("selectRandom: no candidates");
  std::uniform_int_distribution<std::size_t> pick(0, candidates.size() - 1);
  return candidates[pick(rng)];
}

std::vector<double> fvsScores(const Scene& scene, const std::vector<int>& chosen, const std::vector<int>& candidates,
                              ViewDistance metric) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int v : scene.train) c += scene.views[static_cast<std::size_t>(v)].camera.center();
  c /= static_cast<double>(scene.train.size());
  return farthestViewScores(scene, chosen, candidates, metric, c);
}

std::vector<double> farthestViewScores(const Scene& scene, const std::vector<int>& chosen,
                                       const std::vector<int>& candidates, ViewDistance metric,
                                       const Eigen::Vector3d& center) {
  auto dist = [&](int a, int b) {
    const Eigen::Vector3d ca = scene.views.at(a).camera.center(), cb = scene.views.at(b).camera.center();
    if (metric == ViewDistance::kEuclidean) return (ca - cb).norm();
    const Eigen::Vector3d da = ca - center, db = cb - center;
    const double na = da.norm(), nb = db.norm();
    if (!(na > 0) || !(nb > 0)) return 0.0;  // a camera at the centre has no direction
    // atan2 of |cross| and dot is accurate for nearly equal directions, unlike acos.
    return std::atan2(da.cross(db).norm(), da.dot(db));
  };
  std::vector<double> out;
  out.reserve(candidates.size());
  for (int c : candidates) {
    double d = std::numeric_limits<double>::infinity();
    for (int v : chosen) d = std::min(d, dist(c, v));
    out.push_back(chosen.empty() ? 0.0 : d);
  }
  return out;
}

double poseDistance(const Camera& a, const Camera& b, double angle_scale) {
  const Eigen::Vector3d za = a.R.row(2).transpose(), zb = b.R.row(2).transpose();
  // atan2 of |cross| and dot: accurate for nearly parallel axes, unlike acos.
  const double angle = std::atan2(za.cross(zb).norm(), za.dot(zb));
  return (a.center() - b.center()).norm() + angle_scale * angle;
}

double poseAngleScale(const Scene& scene) {
  if (scene.train.empty()) return 1;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int v : scene.train) mean += scene.views.at(v).camera.center();
  mean /= static_cast<double>(scene.train.size());
  std::vector<double> r;
  for (int v : scene.train) r.push_back((scene.views.at(v).camera.center() - mean).norm());
  std::nth_element(r.begin(), r.begin() + static_cast<long>(r.size() / 2), r.end());
  const double median = r[r.size() / 2];
  return median > 0 && std::isfinite(median) ? median : 1;
}

double captureClustering(const Scene& scene, int k) {
  const std::size_t n = scene.train.size();
  if (k < 1 || n <= static_cast<std::size_t>(k)) return 0;
  std::vector<Eigen::Vector3d> c;
  c.reserve(n);
  for (int v : scene.train) c.push_back(scene.views.at(v).camera.center());
  std::vector<double> kth(n), d(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) d[j] = (c[i] - c[j]).norm();
    // d[i] = 0 is the camera itself: its k-th nearest other camera is the (k+1)-th smallest.
    std::nth_element(d.begin(), d.begin() + k, d.end());
    kth[i] = d[static_cast<std::size_t>(k)];
  }
  double mean = 0;
  for (double x : kth) mean += x;
  mean /= static_cast<double>(n);
  if (!(mean > 0) || !std::isfinite(mean)) return 0;
  double var = 0;
  for (double x : kth) var += (x - mean) * (x - mean);
  return std::sqrt(var / static_cast<double>(n)) / mean;
}

std::vector<double> kmedianGains(const Scene& scene, const std::vector<int>& chosen, const std::vector<int>& candidates,
                                 const std::vector<int>& population, double angle_scale,
                                 const std::vector<double>& weights) {
  if (!(angle_scale >= 0) || !std::isfinite(angle_scale))
    throw std::invalid_argument("kmedianGains: angle scale " + std::to_string(angle_scale) +
                                " is not a finite value >= 0");
  if (!weights.empty() && weights.size() != population.size())
    throw std::invalid_argument("kmedianGains: " + std::to_string(weights.size()) + " weights for a population of " +
                                std::to_string(population.size()));
  for (double w : weights)
    if (!(w >= 0) || !std::isfinite(w))
      throw std::invalid_argument("kmedianGains: weight " + std::to_string(w) + " is not finite and >= 0");
  auto d = [&](int a, int b) { return poseDistance(scene.views.at(a).camera, scene.views.at(b).camera, angle_scale); };
  std::vector<double> near(population.size(), 0.0);
  for (std::size_t i = 0; i < population.size(); ++i) {
    if (chosen.empty()) {
      for (int u : population) near[i] = std::max(near[i], d(population[i], u));
    } else {
      near[i] = std::numeric_limits<double>::infinity();
      for (int s : chosen) near[i] = std::min(near[i], d(population[i], s));
    }
  }
  std::vector<double> out;
  out.reserve(candidates.size());
  for (int x : candidates) {
    double gain = 0;
    for (std::size_t i = 0; i < population.size(); ++i)
      gain += (weights.empty() ? 1.0 : weights[i]) * std::max(0.0, near[i] - d(population[i], x));
    out.push_back(gain);
  }
  return out;
}

std::vector<double> fisherScores(const Gaussians& g, const RasterSettings& s, const Scene& scene,
                                 const std::vector<int>& chosen, const std::vector<int>& candidates, double lambda,
                                 const std::function<void(int, int)>& tick, FisherCriterion criterion) {
  Gaussians H = g.zerosLike();
  for (int v : chosen) addViewInformation(g, scene.views.at(v).camera, s, H);
  Gaussians Hv = g.zerosLike();
  std::vector<double> out;
  out.reserve(candidates.size());
  const int total = static_cast<int>(candidates.size());
  for (int c : candidates) {
    if (tick) tick(static_cast<int>(out.size()), total);
    clearInformation(Hv);
    addViewInformation(g, scene.views.at(c).camera, s, Hv);
    out.push_back(criterion == FisherCriterion::kTrace ? fisherScore(Hv, H, lambda) : fisherLogDetScore(Hv, H, lambda));
  }
  if (tick) tick(total, total);
  return out;
}

std::vector<double> hybridScores(const std::vector<double>& fisher, const std::vector<double>& new_surface, double w) {
  if (fisher.size() != new_surface.size()) throw std::invalid_argument("hybridScores: the score lists differ in size");
  if (!(w >= 0 && w <= 1)) throw std::invalid_argument("hybridScores: weight " + std::to_string(w) + " outside [0, 1]");
  auto scale = [](const std::vector<double>& v) {
    double m = 0;
    for (double x : v)
      if (std::isfinite(x)) m = std::max(m, x);
    return m > 0 ? 1.0 / m : 0.0;
  };
  const double sf = scale(fisher), sn = scale(new_surface);
  std::vector<double> out(fisher.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double f = std::isfinite(fisher[i]) ? fisher[i] * sf : 0.0;
    const double n = std::isfinite(new_surface[i]) ? new_surface[i] * sn : 0.0;
    out[i] = (1 - w) * f + w * n;
  }
  return out;
}

std::size_t argmaxScore(const std::vector<double>& scores, const std::vector<int>& candidates) {
  if (scores.empty() || scores.size() != candidates.size()) throw std::invalid_argument("argmaxScore: bad sizes");
  std::size_t best = 0;
  for (std::size_t i = 1; i < scores.size(); ++i) {
    // NaN never wins; equal scores go to the lower view index.
    if (scores[i] > scores[best] || (scores[i] == scores[best] && candidates[i] < candidates[best]) ||
        std::isnan(scores[best]))
      best = i;
  }
  return best;
}

}  // namespace saresgs
