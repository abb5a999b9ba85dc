#include "splat/train/adam.h"
#include "geometry/float_env.h"

#include <cmath>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace saresgs {

namespace {

// The torch formulation p -= lr / bc1 * m / (sqrt(v) / sqrt(bc2) + eps), one value at a
// time in plain loops that vectorise (the library builds with -fno-math-errno, letting
// sqrt vectorise too). Where GCC or Clang builds for x86-64, each loop is also compiled for
// AVX2 and picked at run time (eight lanes of sqrt and division instead of four; AVX2
// without FMA, so the same roundings: the moments and parameters are the same bits).
struct AdamCoeffs {
  float b1, b2, eps, inv_bc1, inv_sqrt_bc2;
};
#if defined(__x86_64__) && defined(__GNUC__)
#define SARESGS_ADAM_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define SARESGS_ADAM_CLONES
#endif

inline void adamValue(float& p, float g, float& m, float& v, float step, const AdamCoeffs& c) {
  const float mi = c.b1 * m + (1.0f - c.b1) * g;
  const float vi = c.b2 * v + (1.0f - c.b2) * g * g;
  m = mi;
  v = vi;
  p -= step * mi / (std::sqrt(vi) * c.inv_sqrt_bc2 + c.eps);
}

// n contiguous values with one step (lr / bc1).
SARESGS_ADAM_CLONES void adamSpan(float* __restrict p, const float* __restrict g, float* __restrict m,
                                  float* __restrict v, std::size_t n, float step, const AdamCoeffs& c) {
  for (std::size_t i = 0; i < n; ++i) adamValue(p[i], g[i], m[i], v[i], step, c);
}

// `rows` rows of kShPer values, value k of each with its own step steps[k] (the SH array:
// DC and the higher bands): one loop over a row's values rather than two short ones.
constexpr std::size_t kShPer = 48;
SARESGS_ADAM_CLONES void adamRows(float* __restrict p, const float* __restrict g, float* __restrict m,
                                  float* __restrict v, std::size_t rows, const float* __restrict steps,
                                  const AdamCoeffs& c) {
  for (std::size_t r = 0; r < rows; ++r) {
    const std::size_t b = r * kShPer;
    for (std::size_t k = 0; k < kShPer; ++k) adamValue(p[b + k], g[b + k], m[b + k], v[b + k], steps[k], c);
  }
}

// Gaussians in blocks, in parallel; `per` floats per Gaussian, of which the first
// `head` use lr_head and the rest lr_tail (the SH array: DC then the higher bands).
void adamArray(std::vector<float>& p, const std::vector<float>& g, std::vector<float>& m, std::vector<float>& v,
               std::size_t per, std::size_t head, float lr_head, float lr_tail, const AdamCoeffs& c) {
  const std::size_t n = per ? p.size() / per : 0;
  const float step_head = lr_head * c.inv_bc1, step_tail = lr_tail * c.inv_bc1;
  float steps[kShPer];
  for (std::size_t k = 0; k < kShPer; ++k) steps[k] = k < head ? step_head : step_tail;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 2048), [&](const tbb::blocked_range<std::size_t>& r) {
    const FloatEnvGuard fenv;  // geometry/float_env.h
    const std::size_t b = r.begin() * per;
    if (head == per) {
      adamSpan(p.data() + b, g.data() + b, m.data() + b, v.data() + b, (r.end() - r.begin()) * per, step_head, c);
      return;
    }
    if (per == kShPer) {
      adamRows(p.data() + b, g.data() + b, m.data() + b, v.data() + b, r.end() - r.begin(), steps, c);
      return;
    }
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const std::size_t o = i * per;
      adamSpan(p.data() + o, g.data() + o, m.data() + o, v.data() + o, head, step_head, c);
      adamSpan(p.data() + o + head, g.data() + o + head, m.data() + o + head, v.data() + o + head, per - head,
               step_tail, c);
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
