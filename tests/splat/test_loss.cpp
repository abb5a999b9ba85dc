#include <gtest/gtest.h>

#include "ssim_oracle.h"
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "splat/loss.h"
#include "splat/metrics.h"
#include "splat/ssim.h"

using namespace saresgs;

namespace {

ImageF randomLossImage(int w, int h, std::uint64_t seed, float lo = 0.0f, float hi = 1.0f) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(lo, hi);
  ImageF img(w, h, 3);
  for (auto& v : img.data) v = u(rng);
  return img;
}

ImageF smoothImage(int w, int h, float phase) {
  ImageF img(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) img.at(x, y, c) = 0.5f + 0.3f * std::sin(0.15f * x + 0.1f * y + c + phase);
  return img;
}

// Like a NeRF-synthetic view: white background, a textured disc, a flat grey patch.
ImageF sceneImage(int w, int h) {
  ImageF img(w, h, 3, 1.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float cx = x - 0.45f * w, cy = y - 0.5f * h;
      for (int c = 0; c < 3; ++c) {
        float v = 1.0f;
        if (std::sqrt(cx * cx + cy * cy) < 0.3f * h)
          v = 0.3f + 0.2f * std::sin(0.2f * x + c) * std::cos(0.25f * y) + 0.05f * std::sin(0.9f * x + 0.7f * y);
        else if (x > 0.75f * w && y > 0.6f * h)
          v = 0.6f + 0.1f * c;
        img.at(x, y, c) = v;
      }
    }
  return img;
}

// img * gain + offset + N(0, sigma) noise.
ImageF perturbed(const ImageF& img, std::uint64_t seed, float sigma, float offset = 0.0f, float gain = 1.0f) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> n(0.0f, 1.0f);
  ImageF out = img;
  for (auto& v : out.data) v = v * gain + offset + sigma * n(rng);
  return out;
}

// Keeps every render/target pair at least `gap` apart so that a finite difference with a
// smaller step never crosses L1's kink.
void separate(const ImageF& render, ImageF& target, float gap) {
  for (std::size_t i = 0; i < target.data.size(); ++i)
    if (std::abs(render.data[i] - target.data[i]) < gap)
      target.data[i] = render.data[i] + (render.data[i] < 0.5f ? 2 * gap : -2 * gap);
}

// A slow, independent double-precision loss: the 11x11 window as an explicit 2-D sum at
// every pixel (no separable filtering), the textbook SSIM formula with G*(x^2) - mx^2,
// and the gradient scattered back through the window explicitly (no "the adjoint is the
// same filter" argument).
struct RefLoss {
  double loss = 0, l1 = 0, ssim = 0;
  std::vector<double> grad;  // same layout as the render
};

RefLoss referenceLoss(const ImageF& x, const ImageF& y, double lambda) {
  std::array<double, 11> k{};
  double sum = 0;
  for (int i = 0; i < 11; ++i) sum += k[i] = std::exp(-(i - 5.0) * (i - 5.0) / (2 * 1.5 * 1.5));
  for (auto& v : k) v /= sum;
  const int w = x.width, h = x.height, C = x.channels;
  const double count = static_cast<double>(w) * h * C, C1 = 1e-4, C2 = 9e-4;
  RefLoss R;
  R.grad.assign(x.data.size(), 0.0);
  double l1 = 0;
  for (std::size_t i = 0; i < x.data.size(); ++i) {
    const double d = static_cast<double>(x.data[i]) - y.data[i];
    l1 += std::abs(d);
    R.grad[i] += (1 - lambda) / count * (d > 0 ? 1 : (d < 0 ? -1 : 0));
  }
  double ssim_sum = 0;
  for (int c = 0; c < C; ++c)
    for (int py = 0; py < h; ++py)
      for (int px = 0; px < w; ++px) {
        double mx = 0, my = 0, sxx = 0, syy = 0, sxy = 0;
        for (int dy = -5; dy <= 5; ++dy)
          for (int dx = -5; dx <= 5; ++dx) {
            const int qx = px + dx, qy = py + dy;
            if (qx < 0 || qx >= w || qy < 0 || qy >= h) continue;
            const double g = k[dx + 5] * k[dy + 5], a = x.at(qx, qy, c), b = y.at(qx, qy, c);
            mx += g * a;
            my += g * b;
            sxx += g * a * a;
            syy += g * b * b;
            sxy += g * a * b;
          }
        const double vx = sxx - mx * mx, vy = syy - my * my, cxy = sxy - mx * my;
        const double A1 = 2 * mx * my + C1, A2 = 2 * cxy + C2;
        const double B1 = mx * mx + my * my + C1, B2 = vx + vy + C2;
        const double S = A1 * A2 / (B1 * B2);
        ssim_sum += S;
        const double dmx = 2 * my * (A2 - A1) / (B1 * B2) - 2 * mx * S * (1 / B1 - 1 / B2);
        const double dsxx = -S / B2, dsxy = 2 * A1 / (B1 * B2), scale = -lambda / count;
        for (int dy = -5; dy <= 5; ++dy)
          for (int dx = -5; dx <= 5; ++dx) {
            const int qx = px + dx, qy = py + dy;
            if (qx < 0 || qx >= w || qy < 0 || qy >= h) continue;
            const double g = k[dx + 5] * k[dy + 5];
            R.grad[x.index(qx, qy, c)] += scale * g * (dmx + 2 * x.at(qx, qy, c) * dsxx + y.at(qx, qy, c) * dsxy);
          }
      }
  R.l1 = l1 / count;
  R.ssim = ssim_sum / count;
  R.loss = (1 - lambda) * R.l1 + lambda * (1 - R.ssim);
  return R;
}

double maxAbs(const std::vector<double>& v) {
  double m = 0;
  for (double g : v) m = std::max(m, std::abs(g));
  return m;
}

// The fast loss against the double reference: loss within `value_rel` relative, the SSIM
// mean within 5e-7 absolute (observed <= 5e-8; ~1e-7 where FMA contraction is on, as with
// SARESGS_NATIVE), and every gradient value within `grad_rel` of the largest.
void expectMatchesReference(const ImageF& render, const ImageF& target, double lambda, double value_rel,
                            double grad_rel, const char* what) {
  SCOPED_TRACE(what);
  const RefLoss ref = referenceLoss(render, target, lambda);
  const LossResult r = photometricLoss(render, target, lambda, true);
  EXPECT_NEAR(r.loss, ref.loss, value_rel * std::abs(ref.loss)) << "lambda " << lambda;
  EXPECT_NEAR(r.l1, ref.l1, 1e-7 * ref.l1);
  EXPECT_NEAR(r.ssim, ref.ssim, 5e-7);
  ASSERT_EQ(r.grad.data.size(), ref.grad.size());
  const double gmax = maxAbs(ref.grad);
  ASSERT_GT(gmax, 0.0);
  double worst = 0;
  for (std::size_t i = 0; i < ref.grad.size(); ++i) worst = std::max(worst, std::abs(r.grad.data[i] - ref.grad[i]));
  EXPECT_LE(worst, grad_rel * gmax) << "lambda " << lambda << ", largest gradient " << gmax;
}

// Pixels to probe: the four corners, points on each border, a few interior ones.
std::vector<std::pair<int, int>> probePixels(int w, int h, std::uint64_t seed) {
  std::vector<std::pair<int, int>> px = {{0, 0},         {w - 1, 0}, {0, h - 1},     {w - 1, h - 1}, {w / 2, 0},
                                         {w / 3, h - 1}, {0, h / 2}, {w - 1, h / 3}, {1, 1},         {w - 2, h - 2}};
  std::mt19937_64 rng(seed);
  for (int i = 0; i < 6; ++i)
    px.emplace_back(std::uniform_int_distribution<int>(0, w - 1)(rng),
                    std::uniform_int_distribution<int>(0, h - 1)(rng));
  return px;
}

// Central finite differences of a loss against an analytic gradient at probe pixels:
// |analytic - fd| <= rel * |fd| + rel * max|gradient|.
template <typename LossFn>
void checkFiniteDifferences(const ImageF& render, const std::vector<double>& grad, LossFn&& loss, double rel,
                            std::uint64_t seed, const char* what) {
  SCOPED_TRACE(what);
  const float step = 1e-3f;
  const double max_grad = maxAbs(grad);
  ASSERT_GT(max_grad, 0.0);
  for (const auto& [px, py] : probePixels(render.width, render.height, seed))
    for (int c = 0; c < render.channels; ++c) {
      ImageF plus = render, minus = render;
      plus.at(px, py, c) += step;
      minus.at(px, py, c) -= step;
      const double delta = static_cast<double>(plus.at(px, py, c)) - static_cast<double>(minus.at(px, py, c));
      const double fd = (loss(plus) - loss(minus)) / delta;
      const double an = grad[render.index(px, py, c)];
      EXPECT_NEAR(an, fd, rel * std::abs(fd) + rel * max_grad) << "pixel (" << px << "," << py << ") channel " << c;
    }
}

std::vector<double> toDouble(const ImageF& img) { return std::vector<double>(img.data.begin(), img.data.end()); }

// Analytic gradients against finite differences, for both implementations: the double
// reference tightly (1e-4, as the original double loss was tested), and the float loss
// to 2e-3: its value carries float rounding (~1e-7 of each SSIM term) that the 1e-3 step
// divides into the difference quotient; the tight check of the float gradient is the
// comparison with the reference gradient.
void checkGradient(const ImageF& render, const ImageF& target, double lambda, std::uint64_t seed) {
  const RefLoss ref = referenceLoss(render, target, lambda);
  checkFiniteDifferences(
      render, ref.grad, [&](const ImageF& r) { return referenceLoss(r, target, lambda).loss; }, 1e-4, seed,
      "double reference vs finite differences");
  const LossResult fast = photometricLoss(render, target, lambda, true);
  checkFiniteDifferences(
      render, toDouble(fast.grad), [&](const ImageF& r) { return photometricLoss(r, target, lambda, false).loss; },
      2e-3, seed, "float loss vs finite differences");
  expectMatchesReference(render, target, lambda, 1e-6, 5e-5, "float loss vs double reference");
}

// checkGradient at every lambda (0, 0.2, 1) on a random w x h render and target (seeds
// `seed` and seed + 1) kept apart by 0.01, with seed + 2 for the finite differences.
void checkGradientOnRandomImages(int w, int h, std::uint64_t seed) {
  for (double lambda : {0.0, 0.2, 1.0}) {
    const ImageF render = randomLossImage(w, h, seed);
    ImageF target = randomLossImage(w, h, seed + 1);
    separate(render, target, 0.01f);
    checkGradient(render, target, lambda, seed + 2);
  }
}

bool allFiniteImage(const LossResult& r) {
  if (!std::isfinite(r.loss) || !std::isfinite(r.l1) || !std::isfinite(r.ssim)) return false;
  for (float g : r.grad.data)
    if (!std::isfinite(g)) return false;
  return true;
}

}  // namespace

TEST(PhotometricLoss, GradientMatchesFiniteDifferences) { checkGradientOnRandomImages(29, 19, 11); }

TEST(PhotometricLoss, GradientMatchesFiniteDifferencesOnSmoothImages) {
  // Smooth images give small local variances, where the SSIM terms are most curved.
  ImageF render(40, 30, 3), target(40, 30, 3);
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 40; ++x)
      for (int c = 0; c < 3; ++c) {
        render.at(x, y, c) = 0.5f + 0.3f * std::sin(0.15f * x + 0.1f * y + c);
        target.at(x, y, c) = 0.45f + 0.35f * std::sin(0.13f * x - 0.12f * y + 0.5f * c);
      }
  separate(render, target, 0.01f);
  for (double lambda : {0.2, 1.0}) checkGradient(render, target, lambda, 21);
}

TEST(PhotometricLoss, GradientMatchesFiniteDifferencesOnImagesSmallerThanTheWindow) {
  checkGradientOnRandomImages(7, 4, 31);
}

TEST(PhotometricLoss, GradientIsNotClampedOutsideTheUnitRange) {
  // Renders may leave [0,1] during training; the loss must stay differentiable there.
  const ImageF render = randomLossImage(24, 18, 41, -0.3f, 1.3f);
  ImageF target = randomLossImage(24, 18, 42);
  separate(render, target, 0.01f);
  checkGradient(render, target, 0.2, 43);
  checkGradient(render, target, 1.0, 44);
  const LossResult r = photometricLoss(render, target, 1.0, false);
  EXPECT_NEAR(r.ssim, test::ssimOracle(render, target), 1e-7);
  EXPECT_GT(std::abs(r.ssim - ssim(render, target)), 1e-4) << "the loss's SSIM must not clamp";
}

TEST(PhotometricLoss, MatchesTheDoubleReference) {
  // Value to 1e-6 relative (observed: <= 4e-7), SSIM mean to 5e-7 (observed: <= 5e-8).
  // Gradient to float tolerance: observed worst |error| / max|gradient| is ~2e-7 on random
  // images and up to ~1.3e-5 on smooth and flat ones, where the covariance and variance
  // maps carry float error of ~1e-8..1e-7 against C2 = 9e-4.
  const int w = 72, h = 56;
  const ImageF scene = sceneImage(w, h);
  struct Case {
    const char* what;
    ImageF render, target;
    double grad_rel;
  };
  const std::vector<Case> cases = {
      {"random", randomLossImage(w, h, 101), randomLossImage(w, h, 102), 2e-6},
      {"smooth", smoothImage(w, h, 0.0f), smoothImage(w, h, 0.4f), 5e-5},
      {"scene, noisy render", perturbed(scene, 103, 0.02f), scene, 5e-5},
      {"scene, slightly noisy render", perturbed(scene, 104, 0.002f), scene, 5e-5},
      {"scene, offset render", perturbed(scene, 105, 0.0f, -0.01f), scene, 5e-5},
      {"scene, gain and offset", perturbed(scene, 106, 0.0005f, 0.01f, 0.97f), scene, 5e-5},
      {"render outside [0,1]", randomLossImage(w, h, 107, -0.3f, 1.3f), scene, 2e-6},
  };
  for (const Case& c : cases)
    for (double lambda : {0.2, 1.0}) expectMatchesReference(c.render, c.target, lambda, 1e-6, c.grad_rel, c.what);
}

TEST(PhotometricLoss, SsimTermEqualsTheMetricForImagesInTheUnitRange) {
  const ImageF render = randomLossImage(64, 48, 51);
  const ImageF target = randomLossImage(64, 48, 52);
  const LossResult r = photometricLoss(render, target, 1.0, false);
  const double metric = ssim(render, target);
  EXPECT_NEAR(r.ssim, metric, 1e-12);  // one kernel, the same inputs
  EXPECT_NEAR(r.loss, 1.0 - metric, 1e-12);
  EXPECT_NEAR(r.ssim, test::ssimOracle(render, target), 1e-7);
}

TEST(PhotometricLoss, L1TermAndMixing) {
  const ImageF render = randomLossImage(33, 21, 61);
  const ImageF target = randomLossImage(33, 21, 62);
  double sum = 0;
  for (std::size_t i = 0; i < render.data.size(); ++i)
    sum += std::abs(static_cast<double>(render.data[i]) - target.data[i]);
  const double l1 = sum / static_cast<double>(render.data.size());
  const LossResult r0 = photometricLoss(render, target, 0.0);
  // Differences are taken in float (one rounding each) and summed in double.
  EXPECT_NEAR(r0.l1, l1, 1e-7 * l1);
  EXPECT_NEAR(r0.loss, r0.l1, 1e-15);
  // At lambda 0 the gradient is exactly sign(d) / count.
  const float g = static_cast<float>(1.0 / static_cast<double>(render.data.size()));
  for (std::size_t i = 0; i < render.data.size(); ++i) {
    const float d = render.data[i] - target.data[i];
    ASSERT_EQ(r0.grad.data[i], d > 0 ? g : (d < 0 ? -g : 0.0f)) << i;
  }
  const LossResult r = photometricLoss(render, target, 0.2);
  EXPECT_EQ(r.l1, r0.l1);
  EXPECT_NEAR(r.loss, 0.8 * r.l1 + 0.2 * (1.0 - r.ssim), 1e-12);
  EXPECT_NEAR(r.ssim, ssim(render, target), 1e-12);
}

TEST(PhotometricLoss, ZeroAtEqualityWithZeroGradient) {
  // Render == target makes the difference maps exactly zero, so S = 1 and every gradient
  // term vanishes exactly, not just to rounding.
  for (const ImageF& img : {randomLossImage(37, 23, 71), sceneImage(40, 30), smoothImage(20, 9, 1)})
    for (double lambda : {0.0, 0.2, 1.0}) {
      const LossResult r = photometricLoss(img, img, lambda);
      EXPECT_EQ(r.l1, 0.0);
      EXPECT_EQ(r.ssim, 1.0);
      EXPECT_EQ(r.loss, 0.0);
      ASSERT_EQ(r.grad.data.size(), img.data.size());
      for (float g : r.grad.data) ASSERT_EQ(g, 0.0f) << "lambda " << lambda;
    }
}

TEST(PhotometricLoss, DeterministicAcrossCallsAndThreadCounts) {
  // Each row is computed by the same operations whichever thread runs it, and row sums
  // are reduced in row order: results must be bit-identical for any thread count.
  const ImageF render = randomLossImage(160, 123, 81);
  const ImageF target = perturbed(render, 82, 0.05f);
  for (bool want_grad : {true, false}) {
    const LossResult a = photometricLoss(render, target, 0.2, want_grad);
    std::vector<LossResult> others{photometricLoss(render, target, 0.2, want_grad)};
    for (int threads : {1, 2, 3}) {
      tbb::task_arena arena(threads);
      arena.execute([&] { others.push_back(photometricLoss(render, target, 0.2, want_grad)); });
    }
    for (const LossResult& r : others) {
      EXPECT_EQ(std::memcmp(&a.loss, &r.loss, sizeof(double)), 0);
      EXPECT_EQ(std::memcmp(&a.ssim, &r.ssim, sizeof(double)), 0);
      EXPECT_EQ(std::memcmp(&a.l1, &r.l1, sizeof(double)), 0);
      ASSERT_EQ(a.grad.data.size(), r.grad.data.size());
      // (memcmp of an empty buffer would pass it null pointers: undefined behaviour.)
      if (!a.grad.data.empty()) {
        EXPECT_EQ(std::memcmp(a.grad.data.data(), r.grad.data.data(), a.grad.data.size() * sizeof(float)), 0);
      }
    }
  }
}

bool sameBits(const LossResult& a, const LossResult& b) {
  return std::memcmp(&a.loss, &b.loss, sizeof(double)) == 0 && a.grad.data.size() == b.grad.data.size() &&
         (a.grad.data.empty() ||
          std::memcmp(a.grad.data.data(), b.grad.data.data(), a.grad.data.size() * sizeof(float)) == 0);
}

// ssimL1 keeps its buffers per thread between calls: a large call, then a smaller one, then
// the large one again give the bits of each size's first call (nothing stale is read), and
// calls running at once on every thread give the bits of the same calls made one at a time.
// (A call nested in another's wait on the same thread takes buffers of its own; this test
// cannot force that nesting, so it does not show it.)
TEST(PhotometricLoss, KeptBuffersLeakNothingBetweenCallsOrThreads) {
  const ImageF big = randomLossImage(150, 97, 5), big_t = perturbed(big, 6, 0.1f);
  const ImageF small = randomLossImage(23, 17, 7), small_t = perturbed(small, 8, 0.1f);
  const LossResult b1 = photometricLoss(big, big_t, 0.2, true);
  const LossResult s1 = photometricLoss(small, small_t, 0.2, true);
  EXPECT_TRUE(sameBits(photometricLoss(big, big_t, 0.2, true), b1));
  EXPECT_TRUE(sameBits(photometricLoss(small, small_t, 0.2, false), photometricLoss(small, small_t, 0.2, false)));
  EXPECT_TRUE(sameBits(photometricLoss(small, small_t, 0.2, true), s1));
  std::vector<LossResult> at_once(24);
  tbb::parallel_for(0, 24, [&](int i) {
    at_once[static_cast<std::size_t>(i)] =
        i % 2 ? photometricLoss(big, big_t, 0.2, true) : photometricLoss(small, small_t, 0.2, true);
  });
  for (int i = 0; i < 24; ++i) EXPECT_TRUE(sameBits(at_once[static_cast<std::size_t>(i)], i % 2 ? b1 : s1)) << i;
}

TEST(PhotometricLoss, EveryVectorWidthGivesIdenticalBits) {
  // The same IEEE operations in the same order per value, 16, 8 or 4 at a time.
  if (ssimBestIsa() == SsimIsa::kBaseline)
    GTEST_SKIP() << "one SSIM build only: no AVX2 on this CPU, or a -march=native / non-x86 build";
  std::vector<SsimIsa> isas = {SsimIsa::kAvx2};
  if (ssimBestIsa() == SsimIsa::kAvx512) isas.push_back(SsimIsa::kAvx512);
  // Widths around the vector lengths and their multiples (the loops' remainders), and 1x1.
  for (const auto& [w, h] : std::vector<std::pair<int, int>>{{160, 123}, {13, 7}, {1, 1}, {17, 33}, {6, 5}}) {
    const ImageF render = randomLossImage(w, h, 111 + w, -0.1f, 1.1f);
    const ImageF target = perturbed(render, 112, 0.05f);
    for (double lambda : {0.0, 0.2}) {
      ssimLimitIsa(SsimIsa::kBaseline);
      const LossResult base = photometricLoss(render, target, lambda);
      const double metric_base = ssim(render, target);
      for (SsimIsa isa : isas) {
        SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h) + " isa " + std::to_string(static_cast<int>(isa)));
        ssimLimitIsa(isa);
        const LossResult fast = photometricLoss(render, target, lambda);
        EXPECT_EQ(ssim(render, target), metric_base);
        EXPECT_EQ(std::memcmp(&fast.loss, &base.loss, sizeof(double)), 0);
        EXPECT_EQ(std::memcmp(&fast.ssim, &base.ssim, sizeof(double)), 0);
        ASSERT_EQ(fast.grad.data.size(), base.grad.data.size());
        EXPECT_EQ(std::memcmp(fast.grad.data.data(), base.grad.data.data(), fast.grad.data.size() * sizeof(float)), 0);
      }
      ssimLimitIsa(SsimIsa::kAvx512);
    }
  }
}

TEST(PhotometricLoss, TinyAndConstantImagesAreFinite) {
  // Images smaller than the window (down to one pixel), thin strips, and constant images
  // (zero variance everywhere, so only C1 and C2 keep the denominators away from zero).
  const std::vector<std::pair<int, int>> sizes = {{1, 1}, {5, 3}, {3, 5}, {1, 12}, {12, 1}, {2, 2}, {11, 11}, {17, 6}};
  for (const auto& [w, h] : sizes) {
    SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h));
    const ImageF render = randomLossImage(w, h, 91 + w), target = randomLossImage(w, h, 92 + h);
    for (double lambda : {0.0, 0.2, 1.0}) {
      const LossResult r = photometricLoss(render, target, lambda);
      EXPECT_TRUE(allFiniteImage(r));
      expectMatchesReference(render, target, lambda, 1e-6, 1e-5, "tiny");
    }
    for (float a : {0.0f, 0.5f, 1.0f})
      for (float b : {0.0f, 0.3f, 1.0f}) {
        const ImageF ca(w, h, 3, a), cb(w, h, 3, b);
        const LossResult r = photometricLoss(ca, cb, 0.2);
        EXPECT_TRUE(allFiniteImage(r)) << a << " vs " << b;
        // Flat and far apart, vd = G*(d^2) - (G*d)^2 is a float difference of two values
        // near d^2 whose true value is ~0 inside: S is good to ~1e-5 there, the loss
        // (dominated by L1) to better than 1e-6.
        const RefLoss ref = referenceLoss(ca, cb, 0.2);
        EXPECT_NEAR(r.ssim, ref.ssim, 1e-5) << a << " vs " << b;
        EXPECT_NEAR(r.loss, ref.loss, 1e-6 * std::max(ref.loss, 1e-3)) << a << " vs " << b;
      }
  }
  for (float a : {0.0f, 0.25f, 1.0f})
    for (float b : {0.0f, 0.75f, 1.0f}) {
      const ImageF ca(64, 40, 3, a), cb(64, 40, 3, b);
      const LossResult r = photometricLoss(ca, cb, 0.2);
      EXPECT_TRUE(allFiniteImage(r)) << a << " vs " << b;
      const RefLoss ref = referenceLoss(ca, cb, 0.2);
      EXPECT_NEAR(r.loss, ref.loss, 1e-6 * std::max(ref.loss, 1e-3)) << a << " vs " << b;
    }
}

TEST(PhotometricLoss, HandlesOtherChannelCounts) {
  for (int channels : {1, 4}) {
    ImageF render(23, 17, channels), target(23, 17, channels);
    std::mt19937_64 rng(channels);
    std::uniform_real_distribution<float> u(0, 1);
    for (auto& v : render.data) v = u(rng);
    for (auto& v : target.data) v = u(rng);
    expectMatchesReference(render, target, 0.2, 1e-6, 1e-5, channels == 1 ? "one channel" : "four channels");
  }
}

TEST(PhotometricLoss, WithoutGradientSameLossAndEmptyGradient) {
  const ImageF render = randomLossImage(20, 15, 91);
  const ImageF target = randomLossImage(20, 15, 92);
  const LossResult with = photometricLoss(render, target, 0.2, true);
  const LossResult without = photometricLoss(render, target, 0.2, false);
  EXPECT_EQ(with.loss, without.loss);
  EXPECT_EQ(with.ssim, without.ssim);
  EXPECT_TRUE(without.grad.empty());
}

TEST(PhotometricLoss, RejectsMismatchedOrEmptyImages) {
  EXPECT_THROW(photometricLoss(ImageF(4, 4, 3), ImageF(4, 5, 3)), std::invalid_argument);
  EXPECT_THROW(photometricLoss(ImageF(4, 4, 3), ImageF(4, 4, 1)), std::invalid_argument);
  EXPECT_THROW(photometricLoss(ImageF(), ImageF()), std::invalid_argument);
}
