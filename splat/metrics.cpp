#include "splat/metrics.h"

#include <algorithm>
#include <array>
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

std::array<double, 11> gaussianWindow() {
  std::array<double, 11> w{};
  double sum = 0;
  for (int i = 0; i < 11; ++i) {
    w[i] = std::exp(-((i - 5) * (i - 5)) / (2.0 * 1.5 * 1.5));
    sum += w[i];
  }
  for (auto& v : w) v /= sum;
  return w;
}

// Separable 11x11 Gaussian filter of one channel with zero padding ("same" size),
// the convolution 3DGS's SSIM uses.
std::vector<double> blur(const std::vector<double>& src, int w, int h) {
  static const auto k = gaussianWindow();
  std::vector<double> tmp(src.size(), 0.0), out(src.size(), 0.0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double s = 0;
      for (int i = -5; i <= 5; ++i) {
        const int xx = x + i;
        if (xx >= 0 && xx < w) s += k[i + 5] * src[static_cast<size_t>(y) * w + xx];
      }
      tmp[static_cast<size_t>(y) * w + x] = s;
    }
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double s = 0;
      for (int i = -5; i <= 5; ++i) {
        const int yy = y + i;
        if (yy >= 0 && yy < h) s += k[i + 5] * tmp[static_cast<size_t>(yy) * w + x];
      }
      out[static_cast<size_t>(y) * w + x] = s;
    }
  return out;
}

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
  constexpr double C1 = 0.01 * 0.01, C2 = 0.03 * 0.03;
  const int w = a.width, h = a.height;
  const size_t n = static_cast<size_t>(w) * h;
  double total = 0;
  for (int c = 0; c < a.channels; ++c) {
    std::vector<double> x(n), y(n), xx(n), yy(n), xy(n);
    for (size_t i = 0; i < n; ++i) {
      x[i] = clamp01(a.data[i * a.channels + c]);
      y[i] = clamp01(b.data[i * b.channels + c]);
      xx[i] = x[i] * x[i];
      yy[i] = y[i] * y[i];
      xy[i] = x[i] * y[i];
    }
    const auto mx = blur(x, w, h), my = blur(y, w, h);
    const auto sxx = blur(xx, w, h), syy = blur(yy, w, h), sxy = blur(xy, w, h);
    for (size_t i = 0; i < n; ++i) {
      const double vx = sxx[i] - mx[i] * mx[i], vy = syy[i] - my[i] * my[i];
      const double cxy = sxy[i] - mx[i] * my[i];
      total += ((2 * mx[i] * my[i] + C1) * (2 * cxy + C2)) /
               ((mx[i] * mx[i] + my[i] * my[i] + C1) * (vx + vy + C2));
    }
  }
  return total / (static_cast<double>(n) * a.channels);
}

}  // namespace saresgs
