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
#include <limits>
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

// The damping of each parameter group (means, log-scales, opacity logits, SH), for scores
// that damp groups apart: their information differs by orders of magnitude (a mean's is
// in 1/length^2, an opacity's is dimensionless), so one lambda is tiny for one group and
// large for another.
struct GroupDamping {
  double means = 1e-6, log_scales = 1e-6, opacities = 1e-6, sh = 1e-6;
};

// lambda_g = max(floor, kappa x the median of group g's nonzero entries of H): a parameter
// no held view has seen then counts as one seen kappa times as well as the typical one,
// not 1/floor times. kappa 0 gives floor everywhere (FisherRF's single lambda).
template <typename T>
GroupDamping relativeDamping(const GaussiansT<T>& H, double kappa, double floor) {
  auto median = [&](const std::vector<T>& v) {
    std::vector<double> nz;
    for (T x : v)
      if (x > T(0)) nz.push_back(static_cast<double>(x));
    if (nz.empty() || kappa <= 0) return floor;
    std::nth_element(nz.begin(), nz.begin() + static_cast<std::ptrdiff_t>(nz.size() / 2), nz.end());
    return std::max(floor, kappa * nz[nz.size() / 2]);
  };
  return {median(H.means), median(H.log_scales), median(H.opacities), median(H.sh)};
}

// FisherRF's damping examined: the share of a candidate's trace score (fisherScore with
// `lambda`) that comes from parameters whose held information H is below `rel` x the
// median of their group's nonzero held information, i.e. from what no held view has
// really seen. Near 1, the score counts unseen parameters at about 1/lambda each and says
// little about anything else. 0 when the score is 0.
template <typename T>
double unseenShare(const GaussiansT<T>& Hv, const GaussiansT<T>& H, double lambda, double rel = 1e-3) {
  // rel x the group's nonzero median (relativeDamping with no floor); a group nobody has
  // seen at all is unseen throughout.
  auto cutOf = [&](const std::vector<T>& h, double c) {
    return std::any_of(h.begin(), h.end(), [](T x) { return x > T(0); }) ? c : std::numeric_limits<double>::infinity();
  };
  GroupDamping cut = relativeDamping(H, rel, 0.0);
  cut = {cutOf(H.means, cut.means), cutOf(H.log_scales, cut.log_scales), cutOf(H.opacities, cut.opacities),
         cutOf(H.sh, cut.sh)};
  double unseen = 0, all = 0;
  auto add = [&](const std::vector<T>& v, const std::vector<T>& h, double threshold) {
    for (std::size_t k = 0; k < v.size(); ++k)
      if (v[k] != T(0)) {
        const double x = static_cast<double>(v[k]) / (static_cast<double>(h[k]) + lambda);
        all += x;
        if (static_cast<double>(h[k]) < threshold) unseen += x;
      }
  };
  add(Hv.means, H.means, cut.means);
  add(Hv.log_scales, H.log_scales, cut.log_scales);
  add(Hv.opacities, H.opacities, cut.opacities);
  add(Hv.sh, H.sh, cut.sh);
  return all > 0 ? unseen / all : 0.0;
}

// The path-variance score of a candidate view with information Hc, given the held views'
// H and a pool of views (the path a person will look along) whose summed information is
// W: under the diagonal Laplace posterior each parameter's variance 1/(H + l) falls to
// 1/(H + Hc + l), and the pool's predicted variance sum_t sum_p H_tp / (H_p + l_p) falls by
//   sum_p W_p Hc_p / ((H_p + l_p)(H_p + Hc_p + l_p)).
// A parameter counts by how much of the pool depends on it (W), and its gain saturates
// where the held views already tell it (H) or where the candidate says a lot (Hc), so
// near-duplicates of held views and views of what nobody will look at score low.
// Rotations excluded, as in fisherScore; double, fixed order.
template <typename T>
double pathVarianceScore(const GaussiansT<T>& Hc, const GaussiansT<T>& H, const GaussiansT<T>& W,
                         const GroupDamping& l) {
  double score = 0;
  auto add = [&](const std::vector<T>& c, const std::vector<T>& h, const std::vector<T>& w, double lambda) {
    for (std::size_t k = 0; k < c.size(); ++k)
      if (c[k] != T(0)) {
        const double hk = static_cast<double>(h[k]) + lambda;
        score += static_cast<double>(w[k]) * static_cast<double>(c[k]) / (hk * (hk + static_cast<double>(c[k])));
      }
  };
  add(Hc.means, H.means, W.means, l.means);
  add(Hc.log_scales, H.log_scales, W.log_scales, l.log_scales);
  add(Hc.opacities, H.opacities, W.opacities, l.opacities);
  add(Hc.sh, H.sh, W.sh, l.sh);
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
