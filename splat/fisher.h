#pragma once
// FisherRF's diagonal information (docs/DESIGN.md). A view's information is, per parameter,
// the sum over its pixels of the squared gradient of the rendered colour (channels
// summed), over means, log-scales, opacity logits and SH (DC and rest); rotations are
// excluded. H_train is the sum over the current train views; a candidate v scores
//   sum_p H_v[p] / (H_train[p] + lambda),
// the trace form of the expected information gain. The view information is also
// templated on the scalar (splat/fisher_detail.h), so that the tests can run the same
// code in double against finite differences.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "geometry/camera/camera.h"
#include "splat/gaussians.h"
#include "splat/rasterize.h"

namespace saresgs {

// Adds view `cam`'s information to `H` (same shape as g; rotations untouched).
void addViewInformation(const Gaussians& g, const Camera& cam, const RasterSettings& s, Gaussians& H);

// sum over the included parameters of Hv / (Htrain + lambda), accumulated in double in a
// fixed order (deterministic).
template <typename T>
double fisherScore(const GaussiansT<T>& Hv, const GaussiansT<T>& Htrain, double lambda) {
  double score = 0;
  auto add = [&](const std::vector<T>& v, const std::vector<T>& t) {
    for (std::size_t k = 0; k < v.size(); ++k)
      if (v[k] != T(0)) score += static_cast<double>(v[k]) / (static_cast<double>(t[k]) + lambda);
  };
  add(Hv.means, Htrain.means);
  add(Hv.log_scales, Htrain.log_scales);
  add(Hv.opacities, Htrain.opacities);
  add(Hv.sh, Htrain.sh);
  return score;
}

// The D-optimal (log-det) gain of adding view v under the diagonal approximation:
// log det(H_train + H_v + lambda) - log det(H_train + lambda) = sum_p log(1 + H_v[p] /
// (H_train[p] + lambda)). Unlike the trace, a parameter's contribution grows only
// logarithmically with the information a view adds to it, so a view that piles
// information on a few parameters scores below one that adds some to many (views that
// repeat what the chosen ones already tell score low in both). Double, fixed order.
template <typename T>
double fisherLogDetScore(const GaussiansT<T>& Hv, const GaussiansT<T>& Htrain, double lambda) {
  double score = 0;
  auto add = [&](const std::vector<T>& v, const std::vector<T>& t) {
    for (std::size_t k = 0; k < v.size(); ++k)
      if (v[k] != T(0)) score += std::log1p(static_cast<double>(v[k]) / (static_cast<double>(t[k]) + lambda));
  };
  add(Hv.means, Htrain.means);
  add(Hv.log_scales, Htrain.log_scales);
  add(Hv.opacities, Htrain.opacities);
  add(Hv.sh, Htrain.sh);
  return score;
}

// Sets every entry of H to zero, keeping its shape (reuse across candidates: streaming
// candidates needs one buffer, whatever their number).
template <typename T>
void clearInformation(GaussiansT<T>& H) {
  H.forEachArray([](std::vector<T>& a, std::size_t) { std::fill(a.begin(), a.end(), T(0)); });
}

// Per-Gaussian uncertainty from the train information, as the quantity rendered for
// AUSE: the sum over the Gaussian's position and scale parameters of 1 / (H + lambda),
// i.e. the diagonal posterior variance of its geometry (what depth error depends on).
std::vector<float> gaussianGeometryVariance(const Gaussians& Htrain, double lambda);

// A copy of `g` at SH degree 0 whose colour is `value` (on all channels), for rendering
// a per-Gaussian scalar with the same compositing as the colour.
Gaussians withScalarColor(const Gaussians& g, const std::vector<float>& value);

}  // namespace saresgs
