// The `flow` lifting module: OpenCV DIS optical flow, both directions, and a
// forward-backward consistency check. OpenCV stays inside this file.
#include <opencv2/core.hpp>
#include <opencv2/video/tracking.hpp>

#include <algorithm>
#include <cmath>

#include "geometry/error.h"
#include "geometry/enum_names.h"
#include "geometry/lifting/sa_points.h"

namespace saresgs {

namespace {

// DIS works on 8-bit single-channel images: Rec. 601 luma of the RGB values, which keeps
// the texture contrast of every channel. Non-finite values count as black.
cv::Mat toGrey8(const ImageF& img) {
  cv::Mat g(img.height, img.width, CV_8UC1);
  for (int y = 0; y < img.height; ++y) {
    auto* row = g.ptr<std::uint8_t>(y);
    for (int x = 0; x < img.width; ++x) {
      float v = img.channels >= 3 ? 0.299f * img.at(x, y, 0) + 0.587f * img.at(x, y, 1) + 0.114f * img.at(x, y, 2)
                                  : img.at(x, y, 0);
      if (!(v > 0.0f)) v = 0.0f;  // also catches NaN
      row[x] = static_cast<std::uint8_t>(std::lround(std::min(v, 1.0f) * 255.0f));
    }
  }
  return g;
}

int disPreset(FlowPreset p) {
  switch (p) {
    case FlowPreset::kUltrafast:
      return cv::DISOpticalFlow::PRESET_ULTRAFAST;
    case FlowPreset::kFast:
      return cv::DISOpticalFlow::PRESET_FAST;
    case FlowPreset::kMedium:
      return cv::DISOpticalFlow::PRESET_MEDIUM;
  }
  return cv::DISOpticalFlow::PRESET_MEDIUM;
}

cv::Mat disFlow(const cv::Mat& from, const cv::Mat& to, const FlowOptions& opts) {
  // A fresh instance per call: DIS keeps buffers between calls, and a new one makes the
  // result a function of the two images only.
  cv::Ptr<cv::DISOpticalFlow> dis = cv::DISOpticalFlow::create(disPreset(opts.preset));
  if (opts.finest_scale >= 0) dis->setFinestScale(opts.finest_scale);
  cv::Mat flow;
  dis->calc(from, to, flow);
  return flow;
}

}  // namespace

FlowPreset parseFlowPreset(const std::string& name) {
  if (name == "ultrafast") return FlowPreset::kUltrafast;
  if (name == "fast") return FlowPreset::kFast;
  if (name == "medium") return FlowPreset::kMedium;
  throw InputError("flow preset", name, "expected ultrafast, fast or medium");
}

const char* flowPresetName(FlowPreset p) {
  return enumName(p, std::array<const char*, 3>{"ultrafast", "fast", "medium"}, "medium");
}

CorrespondenceSet flowCorrespondences(const ImageF& image0, const ImageF& image1, const FlowOptions& opts) {
  if (image0.width != image1.width || image0.height != image1.height)
    throw InputError("flow", "image size",
                     "expected two images of the same size, got " + std::to_string(image0.width) + "x" +
                         std::to_string(image0.height) + " and " + std::to_string(image1.width) + "x" +
                         std::to_string(image1.height));
  CorrespondenceSet out;
  const int W = image0.width, H = image0.height;
  out.candidates = static_cast<std::size_t>(W) * H;
  if (W < 2 || H < 2) return out;
  const cv::Mat g0 = toGrey8(image0), g1 = toGrey8(image1);
  const cv::Mat fwd = disFlow(g0, g1, opts);
  const cv::Mat bwd = disFlow(g1, g0, opts);
  out.matches.reserve(out.candidates / 2);
  // Flow is in pixel-index units (pixel centres at integers); a shift is the same in the
  // camera convention, where the centres sit at +0.5.
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const cv::Vec2f f = fwd.at<cv::Vec2f>(y, x);
      const double qx = x + f[0], qy = y + f[1];
      // Bilinear lookup of the backward flow needs the four neighbours of q.
      if (!(qx >= 0 && qy >= 0 && qx <= W - 1 && qy <= H - 1)) continue;
      const int x0 = std::min(static_cast<int>(qx), W - 2), y0 = std::min(static_cast<int>(qy), H - 2);
      const double ax = qx - x0, ay = qy - y0;
      const cv::Vec2f b00 = bwd.at<cv::Vec2f>(y0, x0), b10 = bwd.at<cv::Vec2f>(y0, x0 + 1);
      const cv::Vec2f b01 = bwd.at<cv::Vec2f>(y0 + 1, x0), b11 = bwd.at<cv::Vec2f>(y0 + 1, x0 + 1);
      double bx = 0, by = 0;
      for (int c = 0; c < 2; ++c) {
        const double v = (1 - ay) * ((1 - ax) * b00[c] + ax * b10[c]) + ay * ((1 - ax) * b01[c] + ax * b11[c]);
        (c == 0 ? bx : by) = v;
      }
      const double ex = f[0] + bx, ey = f[1] + by;
      if (!(std::sqrt(ex * ex + ey * ey) < opts.max_fb_error_px)) continue;
      const Eigen::Vector2d p(x + 0.5, y + 0.5);
      out.matches.push_back({p, p + Eigen::Vector2d(f[0], f[1])});
    }
  return out;
}

LiftingModule flowModule(const FlowOptions& opts) {
  LiftingModule m;
  m.name = "flow";
  m.needs_render = true;
  m.correspond = [opts](const LiftingPair& pair) {
    CorrespondenceSet set = flowCorrespondences(pair.real_image, pair.extrapolated_image, opts);
    if (!opts.epipolar_refine) return set;
    // Thin first: refinement costs a patch search per match.
    const auto thin = subsampleByStride(set.matches, pair.stride, pair.real.K.width, pair.real.K.height);
    set.matches = refineOnEpipolarLines(pair.real, pair.real_image, pair.extrapolated, pair.extrapolated_image, thin,
                                        opts.refine);
    return set;
  };
  return m;
}

}  // namespace saresgs
