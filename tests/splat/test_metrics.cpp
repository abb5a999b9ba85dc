#include <gtest/gtest.h>

#include "ssim_oracle.h"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>
#include <utility>
#include <vector>

#include "splat/metrics.h"

using namespace saresgs;

namespace {

ImageF randomImage(int w, int h, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(0, 1);
  ImageF img(w, h, 3);
  for (auto& v : img.data) v = u(rng);
  return img;
}

}  // namespace

TEST(Metrics, PsnrOfAConstantOffset) {
  ImageF a(32, 16, 3, 0.25f), b(32, 16, 3, 0.35f);
  EXPECT_NEAR(psnr(a, b), 20.0, 1e-5);  // mse = 0.01
  EXPECT_TRUE(std::isinf(psnr(a, a)));
}

TEST(Metrics, PsnrClampsToUnitRange) {
  ImageF a(8, 8, 3, 1.5f), b(8, 8, 3, 1.0f);  // 1.5 counts as 1
  EXPECT_TRUE(std::isinf(psnr(a, b)));
  ImageF n(8, 8, 3, std::nanf(""));
  EXPECT_TRUE(std::isfinite(psnr(n, b)));  // NaN counts as 0, never propagates
}

TEST(Metrics, SsimMatchesAnIndependentImplementation) {
  const ImageF a = randomImage(40, 30, 1);
  ImageF b = a;
  std::mt19937_64 rng(2);
  std::normal_distribution<float> n(0, 0.1f);
  for (auto& v : b.data) v = std::clamp(v + n(rng), 0.0f, 1.0f);
  EXPECT_NEAR(ssim(a, b), test::ssimOracle(a, b), 1e-6);
  EXPECT_NEAR(ssim(a, a), 1.0, 1e-9);
  EXPECT_NEAR(ssim(a, b), ssim(b, a), 1e-12);
  EXPECT_LT(ssim(a, b), 0.99);  // noise is visible to SSIM
}

TEST(Metrics, SsimMatchesTheOracleAtSeveralSizes) {
  // The metric shares the training loss's float kernel; against OpenCV's double blur it
  // agrees to ~1e-8. Sizes below the window, thin strips and a training-sized image.
  for (const auto& [w, h] : std::vector<std::pair<int, int>>{{1, 1}, {5, 3}, {3, 9}, {17, 1}, {33, 21}, {256, 192}}) {
    const ImageF a = randomImage(w, h, 10 + w);
    ImageF b = a;
    std::mt19937_64 rng(11 + h);
    std::normal_distribution<float> n(0, 0.05f);
    for (auto& v : b.data) v = std::clamp(v + n(rng), 0.0f, 1.0f);
    const double s = ssim(a, b);
    EXPECT_TRUE(std::isfinite(s)) << w << "x" << h;
    EXPECT_NEAR(s, test::ssimOracle(a, b), 1e-7) << w << "x" << h;
    EXPECT_EQ(ssim(a, a), 1.0) << w << "x" << h;
  }
  // Constant images: only C1 and C2 keep the denominators positive.
  for (float va : {0.0f, 0.4f, 1.0f})
    for (float vb : {0.0f, 1.0f}) {
      const ImageF a(24, 16, 3, va), b(24, 16, 3, vb);
      EXPECT_NEAR(ssim(a, b), test::ssimOracle(a, b), 1e-5) << va << " vs " << vb;
    }
}

TEST(Metrics, SsimFallsWithNoise) {
  const ImageF a = randomImage(48, 48, 3);
  double last = 1.0;
  for (float s : {0.02f, 0.05f, 0.1f, 0.2f}) {
    ImageF b = a;
    std::mt19937_64 rng(4);
    std::normal_distribution<float> n(0, s);
    for (auto& v : b.data) v += n(rng);
    const double q = ssim(a, b);
    EXPECT_LT(q, last);
    last = q;
  }
}

TEST(Metrics, ShapeMismatchIsAnError) {
  EXPECT_THROW(psnr(ImageF(4, 4, 3), ImageF(4, 5, 3)), std::invalid_argument);
  EXPECT_THROW(ssim(ImageF(4, 4, 3), ImageF(4, 4, 1)), std::invalid_argument);
  EXPECT_THROW(ssim(ImageF(), ImageF()), std::invalid_argument);
}
