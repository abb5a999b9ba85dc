#pragma once
// An independent SSIM for tests: OpenCV's Gaussian blur (11x11, sigma 1.5) with zero
// padding, per channel, no clamping, averaged over pixels and channels.
#include <opencv2/imgproc.hpp>

#include "geometry/image/image.h"

namespace saresgs::test {

inline double ssimOracle(const ImageF& a, const ImageF& b) {
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

}  // namespace saresgs::test
