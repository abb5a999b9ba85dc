#include "splat/loss.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <vector>

// Notation, per channel and pixel p (G is the normalised 11x11 Gaussian, zero padding):
//   mx = G*x, my = G*y, sxx = G*(x^2), syy = G*(y^2), sxy = G*(xy)
//   vx = sxx - mx^2, vy = syy - my^2, cxy = sxy - mx*my
//   A1 = 2 mx my + C1, A2 = 2 cxy + C2, B1 = mx^2 + my^2 + C1, B2 = vx + vy + C2
//   S  = A1 A2 / (B1 B2)
// Taking (mx, sxx, sxy) as the quantities that depend on the render x:
//   dS/dmx  = 2 my (A2 - A1) / (B1 B2) - 2 mx S (1/B1 - 1/B2)
//   dS/dsxx = -S / B2
//   dS/dsxy = 2 A1 / (B1 B2)
// and, since mx = G*x, sxx = G*(x^2), sxy = G*(x y), the chain rule through the filter
// gives for a render pixel q
//   d(sum_p S_p)/dx_q = (G^T * dS/dmx)_q + 2 x_q (G^T * dS/dsxx)_q + y_q (G^T * dS/dsxy)_q.
// G with zero padding is out_p = sum_{q inside} g(p - q) in_q; its adjoint is
// in_q = sum_{p inside} g(p - q) out_p, the same filter because g is symmetric.

namespace saresgs {

namespace {

constexpr int kRadius = 5;
constexpr int kTaps = 2 * kRadius + 1;
constexpr double kC1 = 0.01 * 0.01;
constexpr double kC2 = 0.03 * 0.03;

const std::array<double, kTaps>& window() {
  static const std::array<double, kTaps> w = [] {
    std::array<double, kTaps> k{};
    double sum = 0;
    for (int i = 0; i < kTaps; ++i) {
      const double d = i - kRadius;
      k[i] = std::exp(-d * d / (2.0 * 1.5 * 1.5));
      sum += k[i];
    }
    for (auto& v : k) v /= sum;
    return k;
  }();
  return w;
}

// Applies the separable Gaussian (zero padding, same size) to `m` planes of w*h doubles:
// dst[j] = G * src[j]. `tmp` must hold m planes. Each output row is written by one task,
// always summing in the same order, so the result does not depend on scheduling.
void blurPlanes(const double* const* src, double* const* dst, int m, int w, int h,
                std::vector<double>& tmp) {
  const auto& k = window();
  const std::size_t n = static_cast<std::size_t>(w) * h;
  tmp.resize(n * m);
  const std::size_t rows = static_cast<std::size_t>(m) * h;
  // Horizontal pass.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows, 8), [&](const auto& r) {
    for (std::size_t pr = r.begin(); pr != r.end(); ++pr) {
      const std::size_t j = pr / h, y = pr % h;
      const double* s = src[j] + y * w;
      double* d = tmp.data() + j * n + y * w;
      const int inner_lo = std::min(kRadius, w), inner_hi = std::max(inner_lo, w - kRadius);
      for (int x = 0; x < inner_lo; ++x) {
        double acc = 0;
        for (int i = std::max(-kRadius, -x); i <= std::min(kRadius, w - 1 - x); ++i)
          acc += k[i + kRadius] * s[x + i];
        d[x] = acc;
      }
      // Interior: the kernel is symmetric, so pair the taps at -i and +i.
      for (int x = inner_lo; x < inner_hi; ++x) {
        const double* c = s + x;
        double acc = k[kRadius] * c[0];
        for (int i = 1; i <= kRadius; ++i) acc += k[kRadius + i] * (c[-i] + c[i]);
        d[x] = acc;
      }
      for (int x = inner_hi; x < w; ++x) {
        double acc = 0;
        for (int i = std::max(-kRadius, -x); i <= std::min(kRadius, w - 1 - x); ++i)
          acc += k[i + kRadius] * s[x + i];
        d[x] = acc;
      }
    }
  });
  // Vertical pass: whole rows at a time (contiguous, vectorisable).
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows, 8), [&](const auto& r) {
    for (std::size_t pr = r.begin(); pr != r.end(); ++pr) {
      const std::size_t j = pr / h;
      const int y = static_cast<int>(pr % h);
      double* d = dst[j] + static_cast<std::size_t>(y) * w;
      const double* plane = tmp.data() + j * n;
      const double* c = plane + static_cast<std::size_t>(y) * w;
      const double k0 = k[kRadius];
      for (int x = 0; x < w; ++x) d[x] = k0 * c[x];
      // Symmetric taps in pairs where both rows exist, single taps at the borders.
      for (int i = 1; i <= kRadius; ++i) {
        const double kk = k[kRadius + i];
        const bool up = y - i >= 0, down = y + i < h;
        const double* a = plane + static_cast<std::size_t>(up ? y - i : 0) * w;
        const double* b = plane + static_cast<std::size_t>(down ? y + i : 0) * w;
        if (up && down)
          for (int x = 0; x < w; ++x) d[x] += kk * (a[x] + b[x]);
        else if (up)
          for (int x = 0; x < w; ++x) d[x] += kk * a[x];
        else if (down)
          for (int x = 0; x < w; ++x) d[x] += kk * b[x];
      }
    }
  });
}

}  // namespace

LossResult photometricLoss(const ImageF& render, const ImageF& target, double lambda_ssim,
                           bool want_grad) {
  if (render.empty() || render.width != target.width || render.height != target.height ||
      render.channels != target.channels || render.data.size() != target.data.size() ||
      render.data.size() !=
          static_cast<std::size_t>(render.width) * render.height * render.channels)
    throw std::invalid_argument("photometricLoss: render and target differ in shape or are empty");

  const int w = render.width, h = render.height, C = render.channels;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  const double count = static_cast<double>(n) * C;
  const double lambda = lambda_ssim;

  LossResult res;
  if (want_grad) res.grad = ImageF(w, h, C);

  // L1 and its gradient (sign / count, 0 at equality), row sums reduced in order.
  std::vector<double> row_l1(h, 0.0);
  const double l1_scale = (1.0 - lambda) / count;
  tbb::parallel_for(tbb::blocked_range<int>(0, h, 4), [&](const auto& r) {
    for (int y = r.begin(); y != r.end(); ++y) {
      const std::size_t b = static_cast<std::size_t>(y) * w * C, e = b + static_cast<std::size_t>(w) * C;
      double acc = 0;
      for (std::size_t i = b; i < e; ++i) {
        const double d = static_cast<double>(render.data[i]) - static_cast<double>(target.data[i]);
        acc += std::abs(d);
        if (want_grad)
          res.grad.data[i] = static_cast<float>(d > 0 ? l1_scale : (d < 0 ? -l1_scale : 0.0));
      }
      row_l1[y] = acc;
    }
  });
  double l1_sum = 0;
  for (double v : row_l1) l1_sum += v;
  res.l1 = l1_sum / count;

  // SSIM, one channel at a time.
  const bool ssim_grad = want_grad && lambda != 0.0;
  std::vector<double> x(n), y(n), xx(n), yy(n), xy(n);
  std::vector<double> mx(n), my(n), sxx(n), syy(n), sxy(n);
  std::vector<double> tmp;
  std::vector<double> row_ssim(static_cast<std::size_t>(h) * C, 0.0);
  // Gradient of the loss's SSIM term: loss_ssim = lambda * (1 - sum S / count).
  const double ssim_scale = -lambda / count;
  for (int c = 0; c < C; ++c) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const auto& r) {
      for (std::size_t p = r.begin(); p != r.end(); ++p) {
        const double a = render.data[p * C + c], b = target.data[p * C + c];
        x[p] = a;
        y[p] = b;
        xx[p] = a * a;
        yy[p] = b * b;
        xy[p] = a * b;
      }
    });
    const double* src[5] = {x.data(), y.data(), xx.data(), yy.data(), xy.data()};
    double* dst[5] = {mx.data(), my.data(), sxx.data(), syy.data(), sxy.data()};
    blurPlanes(src, dst, 5, w, h, tmp);

    // SSIM map; the per-pixel partials overwrite the (no longer needed) product planes:
    // xx <- dS/dmx, yy <- dS/dsxx, xy <- dS/dsxy, each scaled to the loss.
    tbb::parallel_for(tbb::blocked_range<int>(0, h, 4), [&](const auto& r) {
      for (int row = r.begin(); row != r.end(); ++row) {
        double acc = 0;
        const std::size_t b = static_cast<std::size_t>(row) * w;
        for (std::size_t p = b; p < b + w; ++p) {
          const double ux = mx[p], uy = my[p];
          const double vx = sxx[p] - ux * ux, vy = syy[p] - uy * uy, cxy = sxy[p] - ux * uy;
          const double A1 = 2 * ux * uy + kC1, A2 = 2 * cxy + kC2;
          const double B1 = ux * ux + uy * uy + kC1, B2 = vx + vy + kC2;
          const double inv = 1.0 / (B1 * B2);
          const double S = A1 * A2 * inv;
          acc += S;
          if (ssim_grad) {
            xx[p] = ssim_scale * (2 * uy * (A2 - A1) * inv - 2 * ux * S * (1.0 / B1 - 1.0 / B2));
            yy[p] = ssim_scale * (-S / B2);
            xy[p] = ssim_scale * (2 * A1 * inv);
          }
        }
        row_ssim[static_cast<std::size_t>(c) * h + row] = acc;
      }
    });
    if (!ssim_grad) continue;

    // Adjoint filter (the same Gaussian) of the partials, then the chain rule per pixel.
    const double* bsrc[3] = {xx.data(), yy.data(), xy.data()};
    double* bdst[3] = {mx.data(), sxx.data(), sxy.data()};
    blurPlanes(bsrc, bdst, 3, w, h, tmp);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const auto& r) {
      for (std::size_t p = r.begin(); p != r.end(); ++p) {
        const double d = x[p] - y[p];
        const double g_l1 = d > 0 ? l1_scale : (d < 0 ? -l1_scale : 0.0);
        const double g = mx[p] + 2 * x[p] * sxx[p] + y[p] * sxy[p];
        res.grad.data[p * C + c] = static_cast<float>(g_l1 + g);
      }
    });
  }
  double ssim_sum = 0;
  for (double v : row_ssim) ssim_sum += v;
  res.ssim = ssim_sum / count;
  res.loss = (1.0 - lambda) * res.l1 + lambda * (1.0 - res.ssim);
  return res;
}

}  // namespace saresgs
