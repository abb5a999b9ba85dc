#include "splat/loss.h"

#include <stdexcept>

#include "splat/ssim.h"

namespace saresgs {

LossResult photometricLoss(const ImageF& render, const ImageF& target, double lambda_ssim, bool want_grad) {
  LossResult res;
  photometricLoss(render, target, lambda_ssim, want_grad, res);
  return res;
}

void photometricLoss(const ImageF& render, const ImageF& target, double lambda_ssim, bool want_grad, LossResult& res) {
  if (render.empty() || render.width != target.width || render.height != target.height ||
      render.channels != target.channels || render.data.size() != target.data.size() ||
      render.data.size() != static_cast<std::size_t>(render.width) * render.height * render.channels)
    throw std::invalid_argument("photometricLoss: render and target differ in shape or are empty");

  const int w = render.width, h = render.height, C = render.channels;
  const double count = static_cast<double>(w) * h * C;
  const double lambda = lambda_ssim;

  // ssimL1 writes every gradient value, so a reused image needs no clearing.
  res.grad.width = want_grad ? w : 0;
  res.grad.height = want_grad ? h : 0;
  res.grad.channels = want_grad ? C : 0;
  res.grad.data.resize(want_grad ? static_cast<std::size_t>(w) * h * C : 0);
  // loss = (1 - lambda) * mean|x - y| + lambda * mean(1 - S).
  const SsimL1Sums sums = ssimL1(render.data.data(), target.data.data(), w, h, C,
                                 want_grad ? res.grad.data.data() : nullptr, (1.0 - lambda) / count, -lambda / count);
  res.l1 = sums.abs_diff / count;
  const double dssim = sums.one_minus_ssim / count;
  res.ssim = 1.0 - dssim;
  res.loss = (1.0 - lambda) * res.l1 + lambda * dssim;
}

}  // namespace saresgs
