#include "splat/train/adam.h"
#include "geometry/float_env.h"

#include <cmath>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace saresgs {

namespace {

// Updates a[0..n) with the learning rate lr_of(index); the torch formulation
// p -= lr / bc1 * m / (sqrt(v) / sqrt(bc2) + eps).
// Updates entries [b, e) of one array with learning rate `lr`: the torch formulation
// p -= lr / bc1 * m / (sqrt(v) / sqrt(bc2) + eps). Plain contiguous loop so that it
// vectorises (the library builds with -fno-math-errno, letting sqrt vectorise too).
struct AdamCoeffs {
  float b1, b2, eps, inv_bc1, inv_sqrt_bc2;
};
inline void adamSpan(float* __restrict p, const float* __restrict g, float* __restrict m, float* __restrict v,
                     std::size_t n, float lr, const AdamCoeffs& c) {
  const float step = lr * c.inv_bc1;
  for (std::size_t i = 0; i < n; ++i) {
    const float gi = g[i];
    const float mi = c.b1 * m[i] + (1.0f - c.b1) * gi;
    const float vi = c.b2 * v[i] + (1.0f - c.b2) * gi * gi;
    m[i] = mi;
    v[i] = vi;
    p[i] -= step * mi / (std::sqrt(vi) * c.inv_sqrt_bc2 + c.eps);
  }
}

// Gaussians in blocks, in parallel; `per` floats per Gaussian, of which the first
// `head` use lr_head and the rest lr_tail (the SH array: DC then the higher bands).
void adamArray(std::vector<float>& p, const std::vector<float>& g, std::vector<float>& m, std::vector<float>& v,
               std::size_t per, std::size_t head, float lr_head, float lr_tail, const AdamCoeffs& c) {
  const std::size_t n = per ? p.size() / per : 0;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 2048), [&](const tbb::blocked_range<std::size_t>& r) {
    const FloatEnvGuard fenv;  // geometry/float_env.h
    if (head == per) {
      const std::size_t b = r.begin() * per, len = (r.end() - r.begin()) * per;
      adamSpan(p.data() + b, g.data() + b, m.data() + b, v.data() + b, len, lr_head, c);
      return;
    }
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const std::size_t b = i * per;
      adamSpan(p.data() + b, g.data() + b, m.data() + b, v.data() + b, head, lr_head, c);
      adamSpan(p.data() + b + head, g.data() + b + head, m.data() + b + head, v.data() + b + head, per - head, lr_tail, c);
    }
  });
}

}  // namespace

void adamStep(Gaussians& params, const Gaussians& grad, AdamState& s, const LearningRates& lr) {
  if (grad.size() != params.size() || s.m.size() != params.size() || s.v.size() != params.size())
    throw std::invalid_argument("adamStep: parameter, gradient and moment sizes differ");
  ++s.step;
  const double t = static_cast<double>(s.step);
  const AdamCoeffs c{s.beta1, s.beta2, s.eps,
                     static_cast<float>(1.0 / (1.0 - std::pow(static_cast<double>(s.beta1), t))),
                     static_cast<float>(1.0 / std::sqrt(1.0 - std::pow(static_cast<double>(s.beta2), t)))};
  adamArray(params.means, grad.means, s.m.means, s.v.means, 3, 3, lr.means, lr.means, c);
  adamArray(params.log_scales, grad.log_scales, s.m.log_scales, s.v.log_scales, 3, 3, lr.log_scales, lr.log_scales, c);
  adamArray(params.rotations, grad.rotations, s.m.rotations, s.v.rotations, 4, 4, lr.rotations, lr.rotations, c);
  adamArray(params.opacities, grad.opacities, s.m.opacities, s.v.opacities, 1, 1, lr.opacities, lr.opacities, c);
  const std::size_t per = static_cast<std::size_t>(params.shCoeffs()) * 3;
  adamArray(params.sh, grad.sh, s.m.sh, s.v.sh, per, 3, lr.sh_dc, lr.sh_rest, c);
}

}  // namespace saresgs
