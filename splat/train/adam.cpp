#include "splat/train/adam.h"

#include <cmath>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace saresgs {

namespace {

// Updates a[0..n) with the learning rate lr_of(index); the torch formulation
// p -= lr / bc1 * m / (sqrt(v) / sqrt(bc2) + eps).
template <typename LrOf>
void adamArray(std::vector<float>& p, const std::vector<float>& g, std::vector<float>& m, std::vector<float>& v,
               const AdamState& s, LrOf lr_of) {
  const double t = static_cast<double>(s.step);
  const float bc1 = static_cast<float>(1.0 - std::pow(static_cast<double>(s.beta1), t));
  const float sqrt_bc2 = static_cast<float>(std::sqrt(1.0 - std::pow(static_cast<double>(s.beta2), t)));
  const float b1 = s.beta1, b2 = s.beta2, eps = s.eps;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, p.size(), 4096), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const float gi = g[i];
      m[i] = b1 * m[i] + (1.0f - b1) * gi;
      v[i] = b2 * v[i] + (1.0f - b2) * gi * gi;
      const float denom = std::sqrt(v[i]) / sqrt_bc2 + eps;
      p[i] -= lr_of(i) / bc1 * m[i] / denom;
    }
  });
}

}  // namespace

void adamStep(Gaussians& params, const Gaussians& grad, AdamState& s, const LearningRates& lr) {
  if (grad.size() != params.size() || s.m.size() != params.size() || s.v.size() != params.size())
    throw std::invalid_argument("adamStep: parameter, gradient and moment sizes differ");
  ++s.step;
  adamArray(params.means, grad.means, s.m.means, s.v.means, s, [&](std::size_t) { return lr.means; });
  adamArray(params.log_scales, grad.log_scales, s.m.log_scales, s.v.log_scales, s,
            [&](std::size_t) { return lr.log_scales; });
  adamArray(params.rotations, grad.rotations, s.m.rotations, s.v.rotations, s, [&](std::size_t) { return lr.rotations; });
  adamArray(params.opacities, grad.opacities, s.m.opacities, s.v.opacities, s, [&](std::size_t) { return lr.opacities; });
  const std::size_t per = static_cast<std::size_t>(params.shCoeffs()) * 3;
  adamArray(params.sh, grad.sh, s.m.sh, s.v.sh, s, [&](std::size_t i) { return i % per < 3 ? lr.sh_dc : lr.sh_rest; });
}

}  // namespace saresgs
