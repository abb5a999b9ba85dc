#pragma once
// Adam as 3DGS uses it (torch.optim.Adam, betas 0.9/0.999, eps 1e-15), one learning
// rate per parameter group: means, log-scales, rotations, opacity logits, SH DC, SH rest.
// Every entry is updated each step, seen or not (dense Adam, like the reference).
#include <cstdint>

#include "splat/gaussians.h"

namespace saresgs {

struct LearningRates {
  float means = 1.6e-4f;  // times extent; decayed by the trainer's schedule
  float log_scales = 5e-3f;
  float rotations = 1e-3f;
  float opacities = 5e-2f;
  float sh_dc = 2.5e-3f;
  float sh_rest = 2.5e-3f / 20.0f;
};

struct AdamState {
  Gaussians m, v;  // first and second moments, the model's shape
  std::int64_t step = 0;
  float beta1 = 0.9f, beta2 = 0.999f, eps = 1e-15f;
  void resetFor(const Gaussians& params) {
    m = params.zerosLike();
    v = params.zerosLike();
    step = 0;
  }
};

// One Adam step of `params` along `grad` (same shape). Deterministic and parallel
// (element-wise, no reductions).
void adamStep(Gaussians& params, const Gaussians& grad, AdamState& state, const LearningRates& lr);
// The same step, leaving `grad` zero: each value is cleared as the step reads it, so a
// training loop needs no separate pass over the gradient before its next backward.
void adamStepClearingGradient(Gaussians& params, Gaussians& grad, AdamState& state, const LearningRates& lr);

}  // namespace saresgs
