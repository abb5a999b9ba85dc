#pragma once
// The 3DGS photometric training loss and its exact gradient with respect to the render:
//   loss = (1 - lambda) * L1 + lambda * (1 - SSIM)
// L1 is the mean |render - target| over pixels and channels. SSIM uses an 11x11 Gaussian
// window (sigma 1.5), C1 = 0.01^2, C2 = 0.03^2, zero padding ("same" size, as 3DGS's
// reference implementation) and is the mean of the SSIM map over pixels and channels.
// Unlike the evaluation metric (metrics.h) nothing is clamped, so the loss is
// differentiable everywhere except where L1 has its kink (render == target, where the
// L1 gradient is taken as 0). Computation is in float (separable filtering, TBB over fixed
// row blocks, sums reduced in double in a fixed order, AVX2 where the CPU has it): the
// loss agrees with a double evaluation to better than 1e-6 relative (typically 1e-8), the
// gradient to ~1e-5 of its largest value, and results are bit-identical from call to
// call, for any thread count, and with or without AVX2.
#include "geometry/image/image.h"

namespace saresgs {

struct LossResult {
  double loss = 0;  // (1 - lambda) * l1 + lambda * (1 - ssim)
  double l1 = 0;    // mean absolute difference
  double ssim = 0;  // mean SSIM (unclamped)
  ImageF grad;      // dLoss/dRender, same shape as the render; empty unless want_grad
};

// Throws std::invalid_argument when the images are empty or differ in shape.
LossResult photometricLoss(const ImageF& render, const ImageF& target, double lambda_ssim = 0.2, bool want_grad = true);
// The same into `into`, whose gradient image is reused (no allocation once it has held
// one this large).
void photometricLoss(const ImageF& render, const ImageF& target, double lambda_ssim, bool want_grad, LossResult& into);

}  // namespace saresgs
