#include "splat/metrics.h"

#include "splat/ssim.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace saresgs {

namespace {

void checkSameShape(const ImageF& a, const ImageF& b) {
  if (a.width != b.width || a.height != b.height || a.channels != b.channels || a.empty())
    throw std::invalid_argument("metrics: images differ in size or are empty");
}

float clamp01(float v) { return std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f; }

}  // namespace

double psnr(const ImageF& a, const ImageF& b) {
  checkSameShape(a, b);
  double se = 0;
  for (size_t i = 0; i < a.data.size(); ++i) {
    const double d = clamp01(a.data[i]) - clamp01(b.data[i]);
    se += d * d;
  }
  const double mse = se / static_cast<double>(a.data.size());
  if (mse <= 0) return std::numeric_limits<double>::infinity();
  return -10.0 * std::log10(mse);
}

double ssim(const ImageF& a, const ImageF& b) {
  checkSameShape(a, b);
  // The same kernel as the training loss (splat/ssim.h), on clamped copies.
  std::vector<float> x(a.data.size()), y(b.data.size());
  for (size_t i = 0; i < x.size(); ++i) {
    x[i] = clamp01(a.data[i]);
    y[i] = clamp01(b.data[i]);
  }
  const SsimL1Sums s = ssimL1(x.data(), y.data(), a.width, a.height, a.channels, nullptr, 0.0, 0.0);
  return 1.0 - s.one_minus_ssim / (static_cast<double>(a.width) * a.height * a.channels);
}

}  // namespace saresgs
