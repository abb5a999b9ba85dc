#pragma once
// Small random Gaussian scenes for the rasterizer tests, and a finite-difference
// gradient checker.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <utility>
#include <vector>

#include "geometry/camera/camera.h"
#include "splat/gaussians.h"
#include "splat/raster_execution.h"
#include "splat/rasterize.h"

namespace saresgs::test {

// The float kernel sets this CPU runs, by name.
inline std::vector<std::pair<const char*, RasterKernels>> runnableKernels() {
  std::vector<std::pair<const char*, RasterKernels>> k{{"baseline", RasterKernels::kBaseline}};
  if (rasterCpuHasAvx2()) k.emplace_back("avx2", RasterKernels::kAvx2);
  return k;
}

// runnableKernels() and, where the CPU has it, avx512, whose forward is avx2's and whose
// backward is avx2's on 32 registers (bit for bit: FloatPath.Avx512BackwardEqualsAvx2BitForBit).
inline std::vector<std::pair<const char*, RasterKernels>> runnableFisherKernels() {
  auto k = runnableKernels();
  if (rasterCpuHasAvx512()) k.emplace_back("avx512", RasterKernels::kAvx512);
  return k;
}

inline Camera smallCamera(int w = 24, int h = 20) {
  const Intrinsics K{.width = w, .height = h, .fx = 0.9 * w, .fy = 0.9 * w, .cx = 0.5 * w + 0.3, .cy = 0.5 * h - 0.2};
  return Camera::lookAt(K, Eigen::Vector3d(0.2, -3.0, 0.4), Eigen::Vector3d(0, 0, 0), Eigen::Vector3d::UnitZ());
}

// n Gaussians around the origin seen by smallCamera: overlapping, some partly off
// screen, some thin (near-degenerate), random rotations and SH.
template <typename T = double>
GaussiansT<T> randomScene(int n, int sh_degree, std::uint64_t seed, double spread = 0.9) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> nd(0, 1);
  std::uniform_real_distribution<double> u(0, 1);
  GaussiansT<T> g;
  g.max_sh_degree = sh_degree;
  g.resize(n);
  const int K = g.shCoeffs();
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) g.means[3 * i + k] = T(spread * nd(rng) * (k == 1 ? 0.3 : 1.0));
    for (int k = 0; k < 3; ++k) g.log_scales[3 * i + k] = T(std::log(0.08 + 0.25 * u(rng)));
    if (i % 4 == 3) g.log_scales[3 * i + 2] = T(std::log(0.004));  // thin
    for (int k = 0; k < 4; ++k) g.rotations[4 * i + k] = T(nd(rng));
    g.opacities[i] = T(nd(rng));
    for (int k = 0; k < K * 3; ++k) g.sh[i * K * 3 + k] = T((k < 3 ? 1.0 : 0.3) * nd(rng));
  }
  return g;
}

// One isotropic float Gaussian of the given scale and opacity logit (SH degree 0): the
// building block of the stiff scenes (test_raster_stability.cpp, test_fisher.cpp).
inline Gaussians oneGaussian(const Eigen::Vector3d& mean, double scale, float logit = 2.0f) {
  Gaussians g;
  g.resize(1);
  for (int k = 0; k < 3; ++k) {
    g.means[k] = static_cast<float>(mean[k]);
    g.log_scales[k] = static_cast<float>(std::log(scale));
  }
  g.rotations = {1, 0, 0, 0};
  g.opacities = {logit};
  g.sh = {0.5f, -0.2f, 0.1f};
  return g;
}

// Six small Gaussians (scale 0.05, opacity logit 3, SH DC (0.7, 0, 0)) where projection
// must take care, for `cam` and the near plane of `s`.
inline Gaussians nearPlaneAndBorderScene(const Camera& cam, const RasterSettings& s) {
  const Eigen::Vector3d C = cam.center(), f = cam.viewDirection();
  const Eigen::Vector3d means[6] = {
      C + double(s.near_plane) * f,                                    // exactly at the near plane
      C + 0.5 * double(s.near_plane) * f,                              // in front of the camera, before it
      C - 1.0 * f,                                                     // behind the camera
      cam.unproject(Eigen::Vector2d(0, 0.5 * cam.K.height), 2.0),      // on the left border
      cam.unproject(Eigen::Vector2d(cam.K.width, cam.K.height), 2.0),  // on the bottom-right corner
      C,                                                               // at the camera centre
  };
  Gaussians g;
  g.resize(6);
  for (int i = 0; i < 6; ++i) {
    for (int k = 0; k < 3; ++k) {
      g.means[3 * i + k] = static_cast<float>(means[i][k]);
      g.log_scales[3 * i + k] = std::log(0.05f);
    }
    g.rotations[4 * i] = 1;
    g.opacities[i] = 3.0f;
    g.sh[3 * i] = 0.7f;
  }
  return g;
}

struct GradCheck {
  int checked = 0, kinks = 0, bad = 0;
};

// Central differences of `loss` for every entry of one parameter array, against the
// analytic gradient. A parameter whose difference quotients at h and h/4 disagree sits
// on a kink of the piecewise-smooth renderer (a pixel crossing an alpha threshold or a
// rectangle edge) and is counted, not compared.
inline void checkGradientArray(std::vector<double>& param, const std::vector<double>& analytic,
                               const std::function<double()>& loss, const char* name, GradCheck& gc) {
  for (std::size_t k = 0; k < param.size(); ++k) {
    const double x0 = param[k];
    auto quotient = [&](double h) {
      param[k] = x0 + h;
      const double lp = loss();
      param[k] = x0 - h;
      const double lm = loss();
      param[k] = x0;
      return (lp - lm) / (2 * h);
    };
    const double h = 1e-6 * std::max(1.0, std::abs(x0));
    const double fd = quotient(h), fd4 = quotient(h / 4);
    if (std::abs(fd - fd4) > 1e-5 * std::max(1.0, std::abs(fd))) {
      ++gc.kinks;
      continue;
    }
    ++gc.checked;
    const double tol = 1e-5 * std::max(1.0, std::abs(fd));
    if (std::abs(analytic[k] - fd) > tol) {
      ++gc.bad;
      ADD_FAILURE() << name << "[" << k << "]: analytic " << analytic[k] << " vs finite difference " << fd;
    }
  }
}

// checkGradientArray for each of g's five parameter arrays against grad's, in
// forEachArray's order.
inline void checkGradients(GaussiansD& g, const GaussiansD& grad, const std::function<double()>& loss, GradCheck& gc) {
  checkGradientArray(g.means, grad.means, loss, "means", gc);
  checkGradientArray(g.log_scales, grad.log_scales, loss, "log_scales", gc);
  checkGradientArray(g.rotations, grad.rotations, loss, "rotations", gc);
  checkGradientArray(g.opacities, grad.opacities, loss, "opacities", gc);
  checkGradientArray(g.sh, grad.sh, loss, "sh", gc);
}

}  // namespace saresgs::test
