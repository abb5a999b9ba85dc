#include <gtest/gtest.h>

#include "ssim_oracle.h"
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "splat/loss.h"
#include "splat/metrics.h"

using namespace saresgs;

namespace {

ImageF randomImage(int w, int h, std::uint64_t seed, float lo = 0.0f, float hi = 1.0f) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(lo, hi);
  ImageF img(w, h, 3);
  for (auto& v : img.data) v = u(rng);
  return img;
}

// Keeps every render/target pair at least `gap` apart so that a finite difference with a
// smaller step never crosses L1's kink.
void separate(const ImageF& render, ImageF& target, float gap) {
  for (std::size_t i = 0; i < target.data.size(); ++i)
    if (std::abs(render.data[i] - target.data[i]) < gap)
      target.data[i] = render.data[i] + (render.data[i] < 0.5f ? 2 * gap : -2 * gap);
}


// Pixels to probe: the four corners, points on each border, a few interior ones.
std::vector<std::pair<int, int>> probePixels(int w, int h, std::uint64_t seed) {
  std::vector<std::pair<int, int>> px = {{0, 0},         {w - 1, 0},     {0, h - 1},
                                         {w - 1, h - 1}, {w / 2, 0},     {w / 3, h - 1},
                                         {0, h / 2},     {w - 1, h / 3}, {1, 1},
                                         {w - 2, h - 2}};
  std::mt19937_64 rng(seed);
  for (int i = 0; i < 6; ++i)
    px.emplace_back(std::uniform_int_distribution<int>(0, w - 1)(rng),
                    std::uniform_int_distribution<int>(0, h - 1)(rng));
  return px;
}

// Central finite differences of the loss against the analytic gradient at probe pixels.
void checkGradient(const ImageF& render, const ImageF& target, double lambda, std::uint64_t seed) {
  const LossResult base = photometricLoss(render, target, lambda, true);
  ASSERT_EQ(base.grad.width, render.width);
  ASSERT_EQ(base.grad.height, render.height);
  ASSERT_EQ(base.grad.channels, render.channels);
  const float step = 1e-3f;
  double max_grad = 0;
  for (float g : base.grad.data) max_grad = std::max(max_grad, std::abs(static_cast<double>(g)));
  ASSERT_GT(max_grad, 0.0);
  for (const auto& [px, py] : probePixels(render.width, render.height, seed))
    for (int c = 0; c < 3; ++c) {
      ImageF plus = render, minus = render;
      plus.at(px, py, c) += step;
      minus.at(px, py, c) -= step;
      const double delta =
          static_cast<double>(plus.at(px, py, c)) - static_cast<double>(minus.at(px, py, c));
      const double fd = (photometricLoss(plus, target, lambda, false).loss -
                         photometricLoss(minus, target, lambda, false).loss) /
                        delta;
      const double an = base.grad.at(px, py, c);
      EXPECT_NEAR(an, fd, 1e-4 * std::abs(fd) + 1e-4 * max_grad)
          << "lambda " << lambda << " pixel (" << px << "," << py << ") channel " << c;
    }
}

}  // namespace

TEST(PhotometricLoss, GradientMatchesFiniteDifferences) {
  for (double lambda : {0.0, 0.2, 1.0}) {
    const ImageF render = randomImage(29, 19, 11);
    ImageF target = randomImage(29, 19, 12);
    separate(render, target, 0.01f);
    checkGradient(render, target, lambda, 13);
  }
}

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
  for (double lambda : {0.0, 0.2, 1.0}) {
    const ImageF render = randomImage(7, 4, 31);
    ImageF target = randomImage(7, 4, 32);
    separate(render, target, 0.01f);
    checkGradient(render, target, lambda, 33);
  }
}

TEST(PhotometricLoss, GradientIsNotClampedOutsideTheUnitRange) {
  // Renders may leave [0,1] during training; the loss must stay differentiable there.
  const ImageF render = randomImage(24, 18, 41, -0.3f, 1.3f);
  ImageF target = randomImage(24, 18, 42);
  separate(render, target, 0.01f);
  checkGradient(render, target, 0.2, 43);
  checkGradient(render, target, 1.0, 44);
  const LossResult r = photometricLoss(render, target, 1.0, false);
  EXPECT_NEAR(r.ssim, test::ssimOracle(render, target), 1e-9);
  EXPECT_GT(std::abs(r.ssim - ssim(render, target)), 1e-4) << "the loss's SSIM must not clamp";
}

TEST(PhotometricLoss, SsimTermEqualsTheMetricForImagesInTheUnitRange) {
  const ImageF render = randomImage(64, 48, 51);
  const ImageF target = randomImage(64, 48, 52);
  const LossResult r = photometricLoss(render, target, 1.0, false);
  const double metric = ssim(render, target);
  EXPECT_NEAR(r.ssim, metric, 1e-12);
  EXPECT_NEAR(r.loss, 1.0 - metric, 1e-12);
  EXPECT_NEAR(r.ssim, test::ssimOracle(render, target), 1e-9);
}

TEST(PhotometricLoss, L1TermAndMixing) {
  const ImageF render = randomImage(33, 21, 61);
  const ImageF target = randomImage(33, 21, 62);
  double sum = 0;
  for (std::size_t i = 0; i < render.data.size(); ++i)
    sum += std::abs(static_cast<double>(render.data[i]) - target.data[i]);
  const double l1 = sum / static_cast<double>(render.data.size());
  const LossResult r0 = photometricLoss(render, target, 0.0);
  EXPECT_NEAR(r0.l1, l1, 1e-12);
  EXPECT_NEAR(r0.loss, l1, 1e-12);
  // At lambda 0 the gradient is exactly sign(d) / count.
  const float g = static_cast<float>(1.0 / static_cast<double>(render.data.size()));
  for (std::size_t i = 0; i < render.data.size(); ++i) {
    const float d = render.data[i] - target.data[i];
    ASSERT_EQ(r0.grad.data[i], d > 0 ? g : (d < 0 ? -g : 0.0f)) << i;
  }
  const LossResult r = photometricLoss(render, target, 0.2);
  EXPECT_NEAR(r.loss, 0.8 * r.l1 + 0.2 * (1.0 - r.ssim), 1e-12);
  EXPECT_NEAR(r.ssim, ssim(render, target), 1e-12);
}

TEST(PhotometricLoss, ZeroAtEqualityWithZeroGradient) {
  const ImageF img = randomImage(37, 23, 71);
  for (double lambda : {0.0, 0.2, 1.0}) {
    const LossResult r = photometricLoss(img, img, lambda);
    EXPECT_EQ(r.l1, 0.0);
    EXPECT_NEAR(r.ssim, 1.0, 1e-14);
    EXPECT_NEAR(r.loss, 0.0, 1e-14);
    ASSERT_EQ(r.grad.data.size(), img.data.size());
    // Scale of a single pixel's gradient elsewhere is 1/count ~ 4e-4.
    for (float g : r.grad.data) ASSERT_LE(std::abs(g), 1e-12f) << "lambda " << lambda;
    if (lambda == 0.0) {
      for (float g : r.grad.data) ASSERT_EQ(g, 0.0f);
    }
  }
}

TEST(PhotometricLoss, DeterministicAcrossCallsAndThreadCounts) {
  const ImageF render = randomImage(160, 120, 81);
  const ImageF target = randomImage(160, 120, 82);
  const LossResult a = photometricLoss(render, target, 0.2);
  const LossResult b = photometricLoss(render, target, 0.2);
  LossResult c;
  tbb::task_arena one(1);
  one.execute([&] { c = photometricLoss(render, target, 0.2); });
  for (const LossResult* r : std::vector<const LossResult*>{&b, &c}) {
    EXPECT_EQ(std::memcmp(&a.loss, &r->loss, sizeof(double)), 0);
    EXPECT_EQ(std::memcmp(&a.ssim, &r->ssim, sizeof(double)), 0);
    EXPECT_EQ(std::memcmp(&a.l1, &r->l1, sizeof(double)), 0);
    ASSERT_EQ(a.grad.data.size(), r->grad.data.size());
    EXPECT_EQ(std::memcmp(a.grad.data.data(), r->grad.data.data(), a.grad.data.size() * sizeof(float)),
              0);
  }
}

TEST(PhotometricLoss, WithoutGradientSameLossAndEmptyGradient) {
  const ImageF render = randomImage(20, 15, 91);
  const ImageF target = randomImage(20, 15, 92);
  const LossResult with = photometricLoss(render, target, 0.2, true);
  const LossResult without = photometricLoss(render, target, 0.2, false);
  EXPECT_EQ(with.loss, without.loss);
  EXPECT_TRUE(without.grad.empty());
}

TEST(PhotometricLoss, RejectsMismatchedOrEmptyImages) {
  EXPECT_THROW(photometricLoss(ImageF(4, 4, 3), ImageF(4, 5, 3)), std::invalid_argument);
  EXPECT_THROW(photometricLoss(ImageF(4, 4, 3), ImageF(4, 4, 1)), std::invalid_argument);
  EXPECT_THROW(photometricLoss(ImageF(), ImageF()), std::invalid_argument);
}
