#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

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

// An independent SSIM: OpenCV's Gaussian blur with zero padding, per channel.
double ssimOracle(const ImageF& a, const ImageF& b) {
  double total = 0;
  for (int c = 0; c < 3; ++c) {
    cv::Mat x(a.height, a.width, CV_64F), y(a.height, a.width, CV_64F);
    for (int r = 0; r < a.height; ++r)
      for (int k = 0; k < a.width; ++k) {
        x.at<double>(r, k) = a.at(k, r, c);
        y.at<double>(r, k) = b.at(k, r, c);
      }
    auto blur = [](const cv::Mat& m) {
      cv::Mat o;
      cv::GaussianBlur(m, o, cv::Size(11, 11), 1.5, 1.5, cv::BORDER_CONSTANT);
      return o;
    };
    const cv::Mat mx = blur(x), my = blur(y);
    const cv::Mat vx = blur(x.mul(x)) - mx.mul(mx), vy = blur(y.mul(y)) - my.mul(my);
    const cv::Mat cxy = blur(x.mul(y)) - mx.mul(my);
    const double C1 = 1e-4, C2 = 9e-4;
    cv::Mat num = (2 * mx.mul(my) + C1).mul(2 * cxy + C2);
    cv::Mat den = (mx.mul(mx) + my.mul(my) + C1).mul(vx + vy + C2);
    total += cv::mean(num / den)[0];
  }
  return total / 3;
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
  EXPECT_NEAR(ssim(a, b), ssimOracle(a, b), 1e-6);
  EXPECT_NEAR(ssim(a, a), 1.0, 1e-9);
  EXPECT_NEAR(ssim(a, b), ssim(b, a), 1e-12);
  EXPECT_LT(ssim(a, b), 0.99);  // noise is visible to SSIM
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
