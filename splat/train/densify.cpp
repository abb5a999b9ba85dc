#include "splat/train/densify.h"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>

#include "geometry/float_env.h"
#include "splat/model_ops.h"

namespace saresgs {

namespace {

float sigmoid(float x) { return 1.0f / (1.0f + std::exp(-x)); }
float logit(float p) { return std::log(p / (1.0f - p)); }

float maxScale(const Gaussians& g, std::size_t i) {
  return std::exp(std::max({g.log_scales[3 * i], g.log_scales[3 * i + 1], g.log_scales[3 * i + 2]}));
}

Eigen::Matrix3f rotationOf(const Gaussians& g, std::size_t i) {
  Eigen::Quaternionf q(g.rotations[4 * i], g.rotations[4 * i + 1], g.rotations[4 * i + 2], g.rotations[4 * i + 3]);
  if (!(q.norm() > 0) || !std::isfinite(q.norm())) return Eigen::Matrix3f::Identity();
  return q.normalized().toRotationMatrix();
}

// Keeps the moments aligned with a gathered model; gathered-in Gaussians listed in
// `fresh` (positions in the new model) start from zero moments.
void gatherAdam(AdamState& adam, const std::vector<int>& idx, std::size_t fresh_from) {
  adam.m = gatherGaussians(adam.m, idx);
  adam.v = gatherGaussians(adam.v, idx);
  for (Gaussians* mom : {&adam.m, &adam.v}) {
    mom->forEachArray([&](std::vector<float>& a, std::size_t per) {
      std::fill(a.begin() + static_cast<std::ptrdiff_t>(fresh_from * per), a.end(), 0.0f);
    });
  }
}

}  // namespace

void keepLargestGradients(std::vector<int>& clone, std::vector<int>& split, const std::vector<float>& mean_grad,
                          std::size_t n, const DensifyOptions& opt) {
  // A clone adds one Gaussian, a split adds split_count - 1 (its parent is removed).
  const std::size_t split_cost = static_cast<std::size_t>(std::max(1, opt.split_count - 1));
  const std::size_t room = opt.max_gaussians > n ? opt.max_gaussians - n : 0;
  if (clone.size() + split.size() * split_cost <= room) return;
  // Candidates ranked by mean gradient, ties to the lower index: a strict total order, so
  // the kept set does not depend on how the selection partitions.
  struct Candidate {
    int index;
    bool is_split;
  };
  std::vector<Candidate> all;
  all.reserve(clone.size() + split.size());
  for (int i : clone) all.push_back({i, false});
  for (int i : split) all.push_back({i, true});
  auto before = [&](const Candidate& a, const Candidate& b) {
    const float ga = mean_grad[static_cast<std::size_t>(a.index)], gb = mean_grad[static_cast<std::size_t>(b.index)];
    return ga != gb ? ga > gb : a.index < b.index;
  };
  std::size_t keep = 0;
  if (split_cost == 1) {
    // Every candidate costs one Gaussian: the `room` best, found by selection.
    keep = std::min(room, all.size());
    std::nth_element(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(keep), all.end(), before);
  } else {
    // Mixed costs: best first while they fit.
    std::sort(all.begin(), all.end(), before);
    for (std::size_t used = 0; keep < all.size(); ++keep) {
      const std::size_t cost = all[keep].is_split ? split_cost : 1;
      if (used + cost > room) break;
      used += cost;
    }
  }
  all.resize(keep);
  clone.clear();
  split.clear();
  for (const Candidate& c : all) (c.is_split ? split : clone).push_back(c.index);
  // Index order, as without the cap: the new model's layout follows the old one's.
  std::sort(clone.begin(), clone.end());
  std::sort(split.begin(), split.end());
}

void accumulateDensifyStats(DensifyStats& st, const std::vector<float>& grad_mean2d, std::span<const float> radii,
                            std::span<const std::uint8_t> visible, int width, int height) {
  const float sx = 0.5f * static_cast<float>(width), sy = 0.5f * static_cast<float>(height);
  // Every Gaussian's statistics on their own, so in parallel (it ran serially every
  // training step: about 0.4 % of the main job's samples, on one core).
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, st.count.size(), 8192), [&](const auto& r) {
    const FloatEnvGuard fenv;  // geometry/float_env.h
    for (std::size_t i = r.begin(); i < r.end(); ++i) {
      if (!visible[i] || !(radii[i] > 0)) continue;
      const float gx = grad_mean2d[2 * i] * sx, gy = grad_mean2d[2 * i + 1] * sy;
      st.grad_accum[i] += std::sqrt(gx * gx + gy * gy);
      st.count[i] += 1;
      st.max_radius[i] = std::max(st.max_radius[i], radii[i]);
    }
  });
}

DensifyReport densifyAndPrune(Gaussians& g, AdamState& adam, DensifyStats& st, const DensifyOptions& opt, double extent,
                              bool prune_big, std::mt19937_64& rng) {
  DensifyReport rep;
  const std::size_t n = g.size();
  const float dense_limit = opt.percent_dense * static_cast<float>(extent);
  std::vector<int> clone, split;
  std::vector<float> mean_grad(n, 0.0f);
  for (std::size_t i = 0; i < n; ++i) {
    if (st.count[i] == 0) continue;
    mean_grad[i] = st.grad_accum[i] / static_cast<float>(st.count[i]);
    if (!(mean_grad[i] >= opt.grad_threshold)) continue;
    (maxScale(g, i) <= dense_limit ? clone : split).push_back(static_cast<int>(i));
  }
  if (opt.max_gaussians > 0) keepLargestGradients(clone, split, mean_grad, n, opt);
  rep.cloned = clone.size();
  rep.split = split.size();

  // New model: originals, then clones, then split children; split parents are dropped
  // with the pruning below.
  std::vector<int> idx(n);
  for (std::size_t i = 0; i < n; ++i) idx[i] = static_cast<int>(i);
  idx.insert(idx.end(), clone.begin(), clone.end());
  for (int s : split)
    for (int k = 0; k < opt.split_count; ++k) idx.push_back(s);
  Gaussians out = gatherGaussians(g, idx);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  const float shrink = std::log(0.8f * static_cast<float>(opt.split_count));
  std::size_t j = n + clone.size();
  for (int s : split) {
    const Eigen::Matrix3f R = rotationOf(g, static_cast<std::size_t>(s));
    for (int k = 0; k < opt.split_count; ++k, ++j) {
      Eigen::Vector3f z;
      for (int a = 0; a < 3; ++a) z[a] = normal(rng) * std::exp(g.log_scales[3 * s + a]);
      const Eigen::Vector3f p = R * z;
      for (int a = 0; a < 3; ++a) {
        out.means[3 * j + a] += p[a];
        out.log_scales[3 * j + a] -= shrink;
      }
    }
  }
  gatherAdam(adam, idx, n);

  std::vector<float> radius(idx.size(), 0.0f);
  for (std::size_t i = 0; i < n; ++i) radius[i] = st.max_radius[i];
  std::vector<std::uint8_t> drop(idx.size(), 0);
  for (int s : split) drop[static_cast<std::size_t>(s)] = 1;
  for (std::size_t i = 0; i < idx.size(); ++i) {
    if (sigmoid(out.opacities[i]) < opt.min_opacity) drop[i] = 1;
    if (prune_big && (radius[i] > opt.max_screen_radius || maxScale(out, i) > opt.max_world_scale * extent))
      drop[i] = 1;
    // A non-finite parameter can only come from a diverged step; such a Gaussian is dropped
    // rather than allowed to poison every render it touches.
    bool finite = std::isfinite(out.opacities[i]);
    for (int a = 0; a < 3 && finite; ++a)
      finite = std::isfinite(out.means[3 * i + a]) && std::isfinite(out.log_scales[3 * i + a]);
    if (!finite) drop[i] = 1;
  }
  std::vector<int> keep;
  keep.reserve(idx.size());
  for (std::size_t i = 0; i < idx.size(); ++i)
    if (!drop[i]) keep.push_back(static_cast<int>(i));
  rep.pruned = idx.size() - keep.size() - split.size();
  g = gatherGaussians(out, keep);
  adam.m = gatherGaussians(adam.m, keep);
  adam.v = gatherGaussians(adam.v, keep);
  st.resize(g.size());
  return rep;
}

void resetOpacity(Gaussians& g, AdamState& adam, float ceiling) {
  const float cap = logit(ceiling);
  for (std::size_t i = 0; i < g.size(); ++i) g.opacities[i] = std::min(g.opacities[i], cap);
  std::fill(adam.m.opacities.begin(), adam.m.opacities.end(), 0.0f);
  std::fill(adam.v.opacities.begin(), adam.v.opacities.end(), 0.0f);
}

}  // namespace saresgs
