#include "geometry/image/image.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <opencv2/imgproc.hpp>

namespace saresgs {

ImageF toFloat(const Image8& img) {
  ImageF out;
  toFloatInto(img, out);
  return out;
}

void toFloatInto(const Image8& img, ImageF& out) {
  out.width = img.width;
  out.height = img.height;
  out.channels = img.channels;
  out.data.resize(img.data.size());
  for (size_t i = 0; i < img.data.size(); ++i) out.data[i] = img.data[i] * (1.0f / 255.0f);
}

Image8 toByte(const ImageF& img) {
  Image8 out(img.width, img.height, img.channels);
  for (size_t i = 0; i < img.data.size(); ++i) {
    float v = img.data[i];
    if (!(v > 0.0f)) v = 0.0f;  // also maps NaN to 0
    if (v > 1.0f) v = 1.0f;
    out.data[i] = static_cast<std::uint8_t>(std::lround(v * 255.0f));
  }
  return out;
}

Image8 resizeImage(const Image8& img, int width, int height) {
  if (width == img.width && height == img.height) return img;
  cv::Mat m(img.height, img.width, CV_8UC(img.channels), const_cast<std::uint8_t*>(img.data.data()));
  cv::Mat r;
  cv::resize(m, r, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  Image8 out(width, height, img.channels);
  for (int y = 0; y < height; ++y)
    std::memcpy(&out.data[out.index(0, y)], r.ptr(y), static_cast<size_t>(width) * img.channels);
  return out;
}

Image8 compositeOnBackground(const Image8& rgba, const float background[3]) {
  if (rgba.channels == 3) return rgba;
  Image8 out(rgba.width, rgba.height, 3);
  for (int y = 0; y < rgba.height; ++y)
    for (int x = 0; x < rgba.width; ++x) {
      const float a = rgba.at(x, y, 3) / 255.0f;
      for (int c = 0; c < 3; ++c) {
        const float v = rgba.at(x, y, c) / 255.0f * a + background[c] * (1.0f - a);
        out.at(x, y, c) = static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
      }
    }
  return out;
}

}  // namespace saresgs
