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
// `clear`: each gradient value is set to zero once read (g is written only then).
SARESGS_ADAM_CLONES void adamSpan(float* __restrict p, float* __restrict g, float* __restrict m, float* __restrict v,
                                  std::size_t n, float step, const AdamCoeffs& c, bool clear) {
  if (clear) {
    for (std::size_t i = 0; i < n; ++i) {
      adamValue(p[i], g[i], m[i], v[i], step, c);
      g[i] = 0.0f;
    }
  } else {
    for (std::size_t i = 0; i < n; ++i) adamValue(p[i], g[i], m[i], v[i], step, c);
  }
}

// `rows` rows of kShPer values, value k of each with its own step steps[k] (the SH array:
// DC and the higher bands): one loop over a row's values rather than two short ones.
constexpr std::size_t kShPer = 48;
SARESGS_ADAM_CLONES void adamRows(float* __restrict p, float* __restrict g, float* __restrict m, float* __restrict v,
                                  std::size_t rows, const float* __restrict steps, const AdamCoeffs& c, bool clear) {
  for (std::size_t r = 0; r < rows; ++r) {
    const std::size_t b = r * kShPer;
    for (std::size_t k = 0; k < kShPer; ++k) adamValue(p[b + k], g[b + k], m[b + k], v[b + k], steps[k], c);
    if (clear)
      for (std::size_t k = 0; k < kShPer; ++k) g[b + k] = 0.0f;
  }
}

// Gaussians [b, e) of one array: `per` floats per Gaussian, of which the first `head` use
// the step step_head and the rest step_tail (the SH array: DC then the higher bands).
void adamBlock(std::vector<float>& p, const std::vector<float>& gc, std::vector<float>& m, std::vector<float>& v,
               std::size_t per, std::size_t head, float step_head, float step_tail, std::size_t b, std::size_t e,
               const AdamCoeffs& c, bool clear) {
  // Written only with `clear` (adamStepClearingGradient, whose gradient is not const).
  float* g = const_cast<float*>(gc.data());
  const std::size_t o = b * per;
  if (head == per) {
    adamSpan(p.data() + o, g + o, m.data() + o, v.data() + o, (e - b) * per, step_head, c, clear);
    return;
  }
  if (per == kShPer) {
    float steps[kShPer];
    for (std::size_t k = 0; k < kShPer; ++k) steps[k] = k < head ? step_head : step_tail;
    adamRows(p.data() + o, g + o, m.data() + o, v.data() + o, e - b, steps, c, clear);
    return;
  }
  for (std::size_t i = b; i != e; ++i) {
    const std::size_t q = i * per;
    adamSpan(p.data() + q, g + q, m.data() + q, v.data() + q, head, step_head, c, clear);
    adamSpan(p.data() + q + head, g + q + head, m.data() + q + head, v.data() + q + head, per - head, step_tail, c,
             clear);
  }
}

void adamUpdate(Gaussians& params, const Gaussians& grad, AdamState& s, const LearningRates& lr, bool clear) {
  if (grad.size() != params.size() || s.m.size() != params.size() || s.v.size() != params.size() ||
      grad.shCoeffs() != params.shCoeffs())
    throw std::invalid_argument("adamStep: parameter, gradient and moment sizes differ");
  ++s.step;
  const double t = static_cast<double>(s.step);
  const AdamCoeffs c{s.beta1, s.beta2, s.eps,
                     static_cast<float>(1.0 / (1.0 - std::pow(static_cast<double>(s.beta1), t))),
                     static_cast<float>(1.0 / std::sqrt(1.0 - std::pow(static_cast<double>(s.beta2), t)))};
  // Every array in one parallel loop over blocks of Gaussians (one fork and join a step
  // instead of five; each value sees the same operations).
  const float lr_scale = c.inv_bc1;
  const std::size_t per_sh = static_cast<std::size_t>(params.shCoeffs()) * 3;
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, params.size(), 1024), [&](const tbb::blocked_range<std::size_t>& r) {
        const FloatEnvGuard fenv;  // geometry/float_env.h
        const std::size_t b = r.begin(), e = r.end();
        const float sm = lr.means * lr_scale, ss = lr.log_scales * lr_scale;
        const float sr = lr.rotations * lr_scale, so = lr.opacities * lr_scale;
        adamBlock(params.means, grad.means, s.m.means, s.v.means, 3, 3, sm, sm, b, e, c, clear);
        adamBlock(params.log_scales, grad.log_scales, s.m.log_scales, s.v.log_scales, 3, 3, ss, ss, b, e, c, clear);
        adamBlock(params.rotations, grad.rotations, s.m.rotations, s.v.rotations, 4, 4, sr, sr, b, e, c, clear);
        adamBlock(params.opacities, grad.opacities, s.m.opacities, s.v.opacities, 1, 1, so, so, b, e, c, clear);
        adamBlock(params.sh, grad.sh, s.m.sh, s.v.sh, per_sh, 3, lr.sh_dc * lr_scale, lr.sh_rest * lr_scale, b, e, c,
                  clear);
      });
}

}  // namespace

void adamStep(Gaussians& params, const Gaussians& grad, AdamState& s, const LearningRates& lr) {
  adamUpdate(params, grad, s, lr, false);
}

void adamStepClearingGradient(Gaussians& params, Gaussians& grad, AdamState& s, const LearningRates& lr) {
  adamUpdate(params, grad, s, lr, true);
}

}  // namespace saresgs
