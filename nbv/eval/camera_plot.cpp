#include "nbv/eval/camera_plot.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstring>

namespace saresgs {

namespace {

// An orthonormal frame with `up` the mean camera up direction (-y of the cameras in
// world), so "above" and "side" mean what a person expects for any dataset convention.
struct Frame {
  Eigen::Vector3d right, forward, up;
};

Frame sceneFrame(const Scene& s) {
  const Eigen::Vector3d up = meanCameraUp(s);
  Eigen::Vector3d fwd = Eigen::Vector3d::Zero();
  for (const auto& v : s.views) fwd += v.camera.viewDirection();
  Eigen::Vector3d right = up.unitOrthogonal();
  fwd -= fwd.dot(up) * up;
  if (fwd.norm() > 1e-6) right = fwd.normalized().cross(up);
  return {right, up.cross(right), up};
}

}  // namespace

Eigen::Vector3d meanCameraUp(const Scene& scene) {
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  for (const auto& v : scene.views) up += -(v.camera.R.transpose() * Eigen::Vector3d::UnitY());
  return up.norm() > 1e-9 ? Eigen::Vector3d(up.normalized()) : Eigen::Vector3d::UnitZ();
}

Image8 plotCameras(const Scene& scene, const std::vector<int>& initial, const std::vector<int>& selected,
                   int panel_size) {
  const Frame f = sceneFrame(scene);
  const int W = 2 * panel_size, H = panel_size + 28;
  cv::Mat img(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
  // Panel 0: above (right, forward); panel 1: side (right, up).
  for (int panel = 0; panel < 2; ++panel) {
    const Eigen::Vector3d ax = f.right, ay = panel == 0 ? f.forward : f.up;
    PlaneBounds b{ax, ay};
    for (const auto& v : scene.views) b.extend(v.camera.center());
    for (const auto& p : scene.points) b.extend(p.xyz);
    const double span = b.span() * 1.1;
    const double cx = b.centerX(), cy = b.centerY();
    const double scale = (panel_size - 20) / span;
    auto px = [&](const Eigen::Vector3d& p) {
      return cv::Point(panel * panel_size + panel_size / 2 + static_cast<int>((p.dot(ax) - cx) * scale),
                       28 + panel_size / 2 - static_cast<int>((p.dot(ay) - cy) * scale));
    };
    for (std::size_t i = 0; i < scene.points.size(); i += std::max<std::size_t>(1, scene.points.size() / 4000))
      cv::circle(img, px(scene.points[i].xyz), 1, cv::Scalar(200, 200, 200), cv::FILLED);
    const double arrow = 0.06 * span;
    auto draw = [&](int v, const cv::Scalar& colour, int radius, bool filled) {
      const Camera& c = scene.views[static_cast<std::size_t>(v)].camera;
      const cv::Point a = px(c.center()), b = px(c.center() + arrow * c.viewDirection());
      cv::line(img, a, b, colour, 1, cv::LINE_AA);
      cv::circle(img, a, radius, colour, filled ? cv::FILLED : 1, cv::LINE_AA);
    };
    for (int v : scene.test) draw(v, cv::Scalar(150, 150, 150), 3, false);
    for (int v : scene.train) draw(v, cv::Scalar(170, 170, 170), 2, true);
    for (int v : selected)
      if (std::find(initial.begin(), initial.end(), v) == initial.end()) draw(v, cv::Scalar(40, 170, 40), 4, true);
    for (int v : initial) draw(v, cv::Scalar(30, 30, 220), 5, true);
    cv::putText(img, panel == 0 ? "from above" : "from the side", cv::Point(panel * panel_size + 8, 20),
                cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  cv::line(img, cv::Point(panel_size, 0), cv::Point(panel_size, H), cv::Scalar(0, 0, 0), 1);
  // The legend sits at the bottom right, clear of the panel titles.
  cv::putText(img, "red: initial  green: selected  grey: candidates  hollow: test", cv::Point(W - 470, H - 10),
              cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(60, 60, 60), 1, cv::LINE_AA);
  Image8 out;
  out.width = W;
  out.height = H;
  out.channels = 3;
  out.data.resize(static_cast<std::size_t>(W) * H * 3);
  cv::Mat rgb;
  cv::cvtColor(img, rgb, cv::COLOR_BGR2RGB);
  std::memcpy(out.data.data(), rgb.data, out.data.size());
  return out;
}

}  // namespace saresgs
