// The reference renderer against closed forms worked out here from the contract in
// splat/rasterize.h (never against numbers obtained by running it).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "splat/raster/reference_renderer.h"
#include "splat/raster/sh.h"

using namespace saresgs;

namespace {

constexpr int kW = 32, kH = 24;

// Identity pose, principal point off the pixel grid so that distances are not symmetric.
Camera testCamera(double cx = 15.3, double cy = 11.7, double f = 30.0) {
  Camera cam;
  cam.K = Intrinsics{kW, kH, f, f, cx, cy};
  return cam;
}

double logit(double o) { return std::log(o / (1.0 - o)); }
double sigmoidHand(double x) { return 1.0 / (1.0 + std::exp(-x)); }

struct Spec {
  Eigen::Vector3d mean{0, 0, 2};
  Eigen::Vector3d scale{0.05, 0.05, 0.05};
  Eigen::Vector4d quat{1, 0, 0, 0};
  double opacity_logit = 0;
  Eigen::Vector3d dc{0, 0, 0};
};

GaussiansD makeModel(const std::vector<Spec>& specs, int degree = 0) {
  GaussiansD g;
  g.max_sh_degree = degree;
  const int K = shCoeffCount(degree);
  for (const Spec& s : specs) {
    for (int k = 0; k < 3; ++k) g.means.push_back(s.mean[k]);
    for (int k = 0; k < 3; ++k) g.log_scales.push_back(std::log(s.scale[k]));
    for (int k = 0; k < 4; ++k) g.rotations.push_back(s.quat[k]);
    g.opacities.push_back(s.opacity_logit);
    for (int k = 0; k < K; ++k)
      for (int c = 0; c < 3; ++c) g.sh.push_back(k == 0 ? s.dc[c] : 0.0);
  }
  return g;
}

std::size_t pix(int i, int j, int w = kW) { return static_cast<std::size_t>(j) * w + i; }

bool allFiniteRender(const ReferenceImage& im) {
  for (double v : im.rgb)
    if (!std::isfinite(v)) return false;
  for (double v : im.alpha)
    if (!std::isfinite(v) || v < 0 || v > 1) return false;
  for (double v : im.depth)
    if (!std::isfinite(v) || v < 0) return false;
  for (double v : im.radii)
    if (!std::isfinite(v) || v < 0) return false;
  return true;
}

}  // namespace

TEST(ReferenceRenderer, ToDoubleCopiesEveryArray) {
  Gaussians g;
  g.max_sh_degree = 1;
  g.resize(2);
  for (std::size_t k = 0; k < g.sh.size(); ++k) g.sh[k] = 0.25f * k;
  g.means[4] = 1.5f;
  g.log_scales[2] = -3.25f;
  g.rotations[7] = 0.125f;
  g.opacities[1] = 2.5f;
  const GaussiansD d = toDouble(g);
  EXPECT_EQ(d.max_sh_degree, 1);
  EXPECT_EQ(d.size(), 2u);
  ASSERT_EQ(d.sh.size(), g.sh.size());
  for (std::size_t k = 0; k < g.sh.size(); ++k) EXPECT_EQ(d.sh[k], 0.25 * k);
  EXPECT_EQ(d.means[4], 1.5);
  EXPECT_EQ(d.log_scales[2], -3.25);
  EXPECT_EQ(d.rotations[7], 0.125);
  EXPECT_EQ(d.opacities[1], 2.5);
}

TEST(ReferenceRenderer, SingleIsotropicGaussianMatchesClosedForm) {
  const Camera cam = testCamera();
  RasterSettings s;
  s.background = {0.25f, 0.5f, 0.75f};
  Spec sp;
  sp.mean = {0, 0, 2};  // on the optical axis: J W Sigma W^T J^T = (f s / z)^2 I
  sp.scale = {0.05, 0.05, 0.05};
  sp.opacity_logit = logit(0.8);
  sp.dc = {0.5, -0.3, -3.0};  // the last channel goes negative and is clamped to 0
  const ReferenceImage im = referenceRender(makeModel({sp}), cam, s);
  ASSERT_EQ(im.width, kW);
  ASSERT_EQ(im.height, kH);

  const double o = sigmoidHand(sp.opacity_logit);
  const double sigma2 = std::pow(30.0 * 0.05 / 2.0, 2) + static_cast<double>(s.eps2d);
  const double h = std::sqrt(2.0 * std::log(255.0 * o) * sigma2);
  const double colour[3] = {kShC0 * 0.5 + 0.5, kShC0 * -0.3 + 0.5, 0.0};
  const double bg[3] = {0.25, 0.5, 0.75};
  EXPECT_EQ(im.visible[0], 1);
  EXPECT_NEAR(im.radii[0], h, 1e-12);

  int covered = 0, cornersSkipped = 0;
  for (int j = 0; j < kH; ++j)
    for (int i = 0; i < kW; ++i) {
      const double dx = i + 0.5 - 15.3, dy = j + 0.5 - 11.7;
      const bool inRect = std::abs(dx) <= h && std::abs(dy) <= h;
      double alpha = std::min(0.99, o * std::exp(-0.5 * (dx * dx + dy * dy) / sigma2));
      if (!inRect || alpha < 1.0 / 255.0) alpha = 0;
      if (inRect && alpha == 0) ++cornersSkipped;
      const std::size_t p = pix(i, j);
      EXPECT_EQ(im.contributors[p], alpha > 0 ? 1 : 0) << i << "," << j;
      covered += alpha > 0;
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(im.rgb[3 * p + c], alpha * colour[c] + (1 - alpha) * bg[c], 1e-12);
      EXPECT_NEAR(im.alpha[p], alpha, 1e-12);
      if (alpha > 0) {
        EXPECT_NEAR(im.depth[p], 2.0, 1e-12);
      } else {
        EXPECT_EQ(im.depth[p], 0.0);
      }
    }
  EXPECT_GT(covered, 20);
  EXPECT_GT(cornersSkipped, 0);  // rectangle corners beyond the 1/255 ellipse
}

TEST(ReferenceRenderer, FrontToBackByDepthNotByIndex) {
  const Camera cam = testCamera();
  RasterSettings s;
  Spec front, back;
  front.mean = {0, 0, 2};
  front.scale = {0.1, 0.1, 0.1};
  front.opacity_logit = logit(0.7);
  front.dc = {1, 0, 0};
  back = front;
  back.mean = {0, 0, 3};
  back.scale = {0.2, 0.2, 0.2};
  back.opacity_logit = logit(0.6);
  back.dc = {0, 0, 1};
  const ReferenceImage a = referenceRender(makeModel({front, back}), cam, s);
  const ReferenceImage b = referenceRender(makeModel({back, front}), cam, s);
  EXPECT_EQ(a.rgb, b.rgb);
  EXPECT_EQ(a.alpha, b.alpha);
  EXPECT_EQ(a.depth, b.depth);
  EXPECT_EQ(a.contributors, b.contributors);

  // Pixel (15, 11): centre (15.5, 11.5), offset (0.2, -0.2) from both means.
  const double d2 = 0.2 * 0.2 + 0.2 * 0.2, eps = s.eps2d;
  const double s1 = std::pow(30 * 0.1 / 2, 2) + eps, s2 = std::pow(30 * 0.2 / 3, 2) + eps;
  const double a1 = sigmoidHand(front.opacity_logit) * std::exp(-0.5 * d2 / s1);
  const double a2 = sigmoidHand(back.opacity_logit) * std::exp(-0.5 * d2 / s2);
  const std::size_t p = pix(15, 11);
  EXPECT_EQ(a.contributors[p], 2);
  EXPECT_NEAR(a.rgb[3 * p + 0], a1 * (kShC0 + 0.5) + (1 - a1) * a2 * 0.5, 1e-12);
  EXPECT_NEAR(a.rgb[3 * p + 1], a1 * 0.5 + (1 - a1) * a2 * 0.5, 1e-12);
  EXPECT_NEAR(a.rgb[3 * p + 2], a1 * 0.5 + (1 - a1) * a2 * (kShC0 + 0.5), 1e-12);
  EXPECT_NEAR(a.alpha[p], 1 - (1 - a1) * (1 - a2), 1e-12);
  EXPECT_NEAR(a.depth[p], (a1 * 2 + (1 - a1) * a2 * 3) / (1 - (1 - a1) * (1 - a2)), 1e-12);
}

TEST(ReferenceRenderer, EqualDepthTiesGoByIndex) {
  const Camera cam = testCamera();
  RasterSettings s;
  Spec red, blue;
  red.mean = {0, 0, 2};
  red.opacity_logit = logit(0.7);
  red.dc = {1, 0, 0};
  blue = red;
  blue.dc = {0, 0, 1};
  const ReferenceImage rb = referenceRender(makeModel({red, blue}), cam, s);
  const ReferenceImage br = referenceRender(makeModel({blue, red}), cam, s);
  const double sig2 = std::pow(30 * 0.05 / 2, 2) + static_cast<double>(s.eps2d);
  const double a = 0.7 * std::exp(-0.5 * (0.2 * 0.2 + 0.2 * 0.2) / sig2);
  const std::size_t p = pix(15, 11);
  const double hi = kShC0 + 0.5;
  // Index 0 is in front.
  EXPECT_NEAR(rb.rgb[3 * p + 0], a * hi + (1 - a) * a * 0.5, 1e-12);
  EXPECT_NEAR(rb.rgb[3 * p + 2], a * 0.5 + (1 - a) * a * hi, 1e-12);
  EXPECT_NEAR(br.rgb[3 * p + 0], a * 0.5 + (1 - a) * a * hi, 1e-12);
  EXPECT_NEAR(br.rgb[3 * p + 2], a * hi + (1 - a) * a * 0.5, 1e-12);
}

TEST(ReferenceRenderer, TransmittanceStopsBeforeTheThirdOpaqueGaussian) {
  // Principal point on a pixel centre: pixel (15, 11) sees G = 1 for all three, so
  // alpha = min(0.99, o) = 0.99 exactly for each.
  const Camera cam = testCamera(15.5, 11.5);
  RasterSettings s;
  s.background = {1.0f, 1.0f, 1.0f};
  std::vector<Spec> specs(3);
  for (int k = 0; k < 3; ++k) {
    specs[k].mean = {0, 0, 2.0 + k};
    specs[k].scale = {0.1, 0.1, 0.1};
    specs[k].opacity_logit = 30;
    specs[k].dc = {0, 0, 0};
    specs[k].dc[k] = 1;  // red, green, blue from front to back
  }
  const ReferenceImage im = referenceRender(makeModel(specs), cam, s);
  const std::size_t p = pix(15, 11);
  // T after two is (1 - 0.99)^2 = 1e-4 (>= 1e-4 in double arithmetic: 1 - 0.99 rounds
  // to 0.010000000000000009), the third would leave 1e-6 < 1e-4: it stops there.
  EXPECT_EQ(im.contributors[p], 2);
  const double a = 0.99, T = (1 - a) * (1 - a);
  EXPECT_NEAR(im.rgb[3 * p + 0], a * (kShC0 + 0.5) + (1 - a) * a * 0.5 + T, 1e-12);
  EXPECT_NEAR(im.rgb[3 * p + 1], a * 0.5 + (1 - a) * a * (kShC0 + 0.5) + T, 1e-12);
  EXPECT_NEAR(im.rgb[3 * p + 2], a * 0.5 + (1 - a) * a * 0.5 + T, 1e-12);
  EXPECT_NEAR(im.alpha[p], 1 - T, 1e-12);
  EXPECT_NEAR(im.depth[p], (a * 2 + (1 - a) * a * 3) / (1 - T), 1e-12);
}

TEST(ReferenceRenderer, TransmittanceStopClearOfRounding) {
  // Alphas 0.98, 0.99, 0.99 at pixel (15, 11): T goes 0.02, 2e-4, then 2e-6 < 1e-4.
  const Camera cam = testCamera(15.5, 11.5);
  RasterSettings s;
  std::vector<Spec> specs(4);
  const double logits[4] = {logit(0.98), 30, 30, 30};
  for (int k = 0; k < 4; ++k) {
    specs[k].mean = {0, 0, 2.0 + k};
    specs[k].scale = {0.1, 0.1, 0.1};
    specs[k].opacity_logit = logits[k];
    specs[k].dc = {1, 1, 1};
  }
  const ReferenceImage im = referenceRender(makeModel(specs), cam, s);
  const std::size_t p = pix(15, 11);
  EXPECT_EQ(im.contributors[p], 2);
  EXPECT_NEAR(im.alpha[p], 1 - 0.02 * 0.01, 1e-12);
  const double c = kShC0 + 0.5;
  EXPECT_NEAR(im.rgb[3 * p], 0.98 * c + 0.02 * 0.99 * c, 1e-12);
  // With the second one removed the third composites: 0.98 then 0.99, 0.99 again stops.
  specs.erase(specs.begin() + 1);
  const ReferenceImage im2 = referenceRender(makeModel(specs), cam, s);
  EXPECT_EQ(im2.contributors[p], 2);
  EXPECT_NEAR(im2.depth[p], (0.98 * 2 + 0.02 * 0.99 * 4) / (1 - 0.02 * 0.01), 1e-12);
}

TEST(ReferenceRenderer, LowAlphaIsSkippedAndLowOpacityCulled) {
  const Camera cam = testCamera();
  RasterSettings s;
  // o = 0.005: alpha = 0.005 G, skipped where G < 0.784 though inside the rectangle.
  const Spec faint{.mean = {0, 0, 2}, .scale = {0.1, 0.1, 0.1}, .opacity_logit = logit(0.005), .dc = {1, 1, 1}};
  const ReferenceImage im = referenceRender(makeModel({faint}), cam, s);
  ASSERT_EQ(im.visible[0], 1);
  const double sig2 = std::pow(30 * 0.1 / 2, 2) + static_cast<double>(s.eps2d);
  const double o = sigmoidHand(faint.opacity_logit);
  const double h = std::sqrt(2 * std::log(255 * o) * sig2);
  EXPECT_NEAR(im.radii[0], h, 1e-12);
  int drawn = 0, skipped = 0;
  for (int j = 0; j < kH; ++j)
    for (int i = 0; i < kW; ++i) {
      const double dx = i + 0.5 - 15.3, dy = j + 0.5 - 11.7;
      if (std::abs(dx) > h || std::abs(dy) > h) continue;
      const double a = o * std::exp(-0.5 * (dx * dx + dy * dy) / sig2);
      const std::size_t p = pix(i, j);
      if (a < 1.0 / 255.0) {
        ++skipped;
        EXPECT_EQ(im.contributors[p], 0);
        EXPECT_EQ(im.rgb[3 * p], 0.0);
      } else {
        ++drawn;
        EXPECT_EQ(im.contributors[p], 1);
      }
    }
  EXPECT_GT(drawn, 0);
  EXPECT_GT(skipped, 0);

  // Opacity just below 1/255 is culled, just above is not.
  Spec below = faint, above = faint;
  below.opacity_logit = logit(0.999 / 255);
  above.opacity_logit = logit(1.001 / 255);
  const ReferenceImage c = referenceRender(makeModel({below, above}), cam, s);
  EXPECT_EQ(c.visible[0], 0);
  EXPECT_EQ(c.radii[0], 0.0);
  EXPECT_EQ(c.visible[1], 1);
  EXPECT_NEAR(c.radii[1], std::sqrt(2 * std::log(1.001) * sig2), 1e-9);
}

TEST(ReferenceRenderer, MaskEqualsZeroOpacityBitForBit) {
  const Camera cam = testCamera();
  RasterSettings s;
  s.background = {0.1f, 0.2f, 0.3f};
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Spec> specs(12);
  for (Spec& sp : specs) {
    sp.mean = {0.5 * u(rng), 0.4 * u(rng), 2.5 + u(rng)};
    sp.scale = {0.05 + 0.04 * u(rng), 0.05 + 0.04 * u(rng), 0.05 + 0.04 * u(rng)};
    sp.quat = {u(rng), u(rng), u(rng), u(rng)};
    sp.opacity_logit = 2 * u(rng);
    sp.dc = {u(rng), u(rng), u(rng)};
  }
  GaussiansD g = makeModel(specs);
  std::vector<std::uint8_t> mask(specs.size(), 1);
  mask[2] = mask[5] = mask[11] = 0;
  const ReferenceImage masked = referenceRender(g, cam, s, mask);
  for (int k : {2, 5, 11}) g.opacities[k] = -1e9;
  const ReferenceImage zeroed = referenceRender(g, cam, s);
  EXPECT_EQ(masked.rgb, zeroed.rgb);
  EXPECT_EQ(masked.alpha, zeroed.alpha);
  EXPECT_EQ(masked.depth, zeroed.depth);
  EXPECT_EQ(masked.contributors, zeroed.contributors);
  EXPECT_EQ(masked.radii, zeroed.radii);
  EXPECT_EQ(masked.visible, zeroed.visible);
  EXPECT_EQ(masked.visible[5], 0);
  // The mask changed something (the masked Gaussians were on screen).
  const ReferenceImage all = referenceRender(makeModel(specs), cam, s);
  EXPECT_NE(all.rgb, masked.rgb);
}

TEST(ReferenceRenderer, CullingNearPlaneBehindAndGuardBand) {
  const Camera cam = testCamera();
  RasterSettings s;
  const double near = s.near_plane, g = s.guard_band;
  Spec base;
  base.scale = {0.5, 0.5, 0.5};
  base.opacity_logit = 2;
  std::vector<Spec> specs(9, base);
  specs[0].mean = {0, 0, -1};            // behind
  specs[1].mean = {0, 0, near * 0.999};  // just in front of the near plane
  specs[2].mean = {0, 0, near};          // exactly on it: kept
  // Guard band in x: the centre of [l, r] is (W/2 - cx)/fx, the half width W/(2 fx).
  const double z = 2, mx = (16 - 15.3) / 30, hwx = 16.0 / 30;
  const double my = (12 - 11.7) / 30, hwy = 12.0 / 30;
  specs[3].mean = {z * (mx + g * hwx * 0.999), 0, z};
  specs[4].mean = {z * (mx + g * hwx * 1.001), 0, z};
  specs[5].mean = {z * (mx - g * hwx * 0.999), 0, z};
  specs[6].mean = {z * (mx - g * hwx * 1.001), 0, z};
  specs[7].mean = {0, z * (my + g * hwy * 0.999), z};
  specs[8].mean = {0, z * (my + g * hwy * 1.001), z};
  const ReferenceImage im = referenceRender(makeModel(specs), cam, s);
  const std::uint8_t expected[9] = {0, 0, 1, 1, 0, 1, 0, 1, 0};
  for (int k = 0; k < 9; ++k) {
    EXPECT_EQ(im.visible[k], expected[k]) << k;
    if (!expected[k])
      EXPECT_EQ(im.radii[k], 0.0) << k;
    else
      EXPECT_GT(im.radii[k], 0.0) << k;
  }
  EXPECT_TRUE(allFiniteRender(im));

  // Inside a wide guard band but with a rectangle that misses the image: culled.
  RasterSettings wide = s;
  wide.guard_band = 3;
  Spec off = base;
  off.scale = {0.01, 0.01, 0.01};
  off.mean = {(-10 - 15.3) / 30 * 2, 0, 2};  // 2D mean at u = -10
  Spec offBig = off;
  offBig.scale = {0.3, 0.3, 0.3};  // sigma ~ 4.5 px, rectangle reaches past u = 0
  const ReferenceImage w = referenceRender(makeModel({off, offBig}), cam, wide);
  EXPECT_EQ(w.visible[0], 0);
  EXPECT_EQ(w.radii[0], 0.0);
  EXPECT_EQ(w.visible[1], 1);
}

TEST(ReferenceRenderer, ExtentRulesMatchHandComputation) {
  const Camera cam = testCamera();
  // On the axis at depth z, rotated by theta about the camera z axis, scales (sa, sb, sc):
  // Sigma2D = (f/z)^2 Rz diag(sa^2, sb^2) Rz^T + eps I. The second case is axis aligned
  // and nearly opaque, so that just outside the 3-sigma box o G > 1/255 and only the
  // rectangle test keeps those pixels empty.
  struct Case {
    double theta, opacity;
  };
  int cutByThreeSigmaBox = 0;
  for (const Case cs : {Case{0.6, 0.6}, Case{0.0, 0.95}}) {
    const double theta = cs.theta, sa = 0.2, sb = 0.05, sc = 0.3, z = 2.5, f = 30;
    Spec sp;
    sp.mean = {0, 0, z};
    sp.scale = {sa, sb, sc};
    sp.quat = {std::cos(theta / 2), 0, 0, std::sin(theta / 2)};
    sp.opacity_logit = logit(cs.opacity);
    sp.dc = {1, 1, 1};
    const GaussiansD g = makeModel({sp});
    RasterSettings s;
    const double eps = s.eps2d, k = (f / z) * (f / z), co = std::cos(theta), si = std::sin(theta);
    const double a = k * (sa * sa * co * co + sb * sb * si * si) + eps;
    const double c = k * (sa * sa * si * si + sb * sb * co * co) + eps;
    const double b = k * (sa * sa - sb * sb) * co * si;
    const double o = sigmoidHand(sp.opacity_logit);

    s.extent = ExtentRule::kOpacityAware;
    const ReferenceImage oa = referenceRender(g, cam, s);
    const double hx = std::sqrt(2 * std::log(255 * o) * a);
    const double hy = std::sqrt(2 * std::log(255 * o) * c);
    EXPECT_NEAR(oa.radii[0], std::max(hx, hy), 1e-9);
    s.extent = ExtentRule::kThreeSigma;
    const ReferenceImage ts = referenceRender(g, cam, s);
    const double mid = (a + c) / 2, lmax = mid + std::sqrt(mid * mid - (a * c - b * b));
    EXPECT_NEAR(ts.radii[0], 3 * std::sqrt(lmax), 1e-9);

    // Every pixel's alpha follows the hand-made conic inside each rule's rectangle.
    const double det = a * c - b * b;
    for (const auto* im : {&oa, &ts}) {
      const double rx = im == &oa ? hx : 3 * std::sqrt(lmax), ry = im == &oa ? hy : rx;
      for (int j = 0; j < kH; ++j)
        for (int i = 0; i < kW; ++i) {
          const double dx = i + 0.5 - 15.3, dy = j + 0.5 - 11.7;
          double al = o * std::exp(-0.5 * (c * dx * dx - 2 * b * dx * dy + a * dy * dy) / det);
          const bool outside = std::abs(dx) > rx || std::abs(dy) > ry;
          if (outside && al >= 1.0 / 255) cutByThreeSigmaBox += im == &ts;
          if (outside || al < 1.0 / 255) al = 0;
          EXPECT_NEAR(im->alpha[pix(i, j)], al, 1e-12) << i << "," << j;
        }
    }
  }
  EXPECT_GT(cutByThreeSigmaBox, 0);
}

TEST(ReferenceRenderer, OffAxisProjectionWithRotatedCamera) {
  // An independent oracle with Eigen's quaternion and matrices, camera from lookAt.
  Intrinsics K{kW, kH, 28, 31, 14.2, 12.9};
  const Camera cam = Camera::lookAt(K, {1.0, -2.0, 0.5}, {0.1, 0.2, 0.3});
  const Spec sp{.mean = {0.25, 0.1, 0.4},
                .scale = {0.15, 0.04, 0.08},
                .quat = {0.8, -0.3, 0.4, 0.2},
                .opacity_logit = 1.2,
                .dc = {0.3, 0.6, 0.9}};
  RasterSettings s;
  const ReferenceImage im = referenceRender(makeModel({sp}), cam, s);
  ASSERT_EQ(im.visible[0], 1);

  const Eigen::Vector3d p = cam.R * sp.mean + cam.t;
  const Eigen::Matrix3d Rq =
      Eigen::Quaterniond(sp.quat[0], sp.quat[1], sp.quat[2], sp.quat[3]).normalized().toRotationMatrix();
  const Eigen::Matrix3d Sig = Rq * sp.scale.cwiseAbs2().asDiagonal() * Rq.transpose();
  Eigen::Matrix<double, 2, 3> J;
  const double z2 = p.z() * p.z();
  J << K.fx / p.z(), 0, -K.fx * p.x() / z2,  //
      0, K.fy / p.z(), -K.fy * p.y() / z2;
  const Eigen::Matrix2d S2 =
      J * cam.R * Sig * cam.R.transpose() * J.transpose() + double(s.eps2d) * Eigen::Matrix2d::Identity();
  const Eigen::Matrix2d inv = S2.inverse();
  const Eigen::Vector2d mu(K.fx * p.x() / p.z() + K.cx, K.fy * p.y() / p.z() + K.cy);
  const double o = sigmoidHand(sp.opacity_logit);
  const double l = std::log(255 * o);
  const double hx = std::sqrt(2 * l * S2(0, 0)), hy = std::sqrt(2 * l * S2(1, 1));
  EXPECT_NEAR(im.radii[0], std::max(hx, hy), 1e-9);
  int covered = 0;
  for (int j = 0; j < kH; ++j)
    for (int i = 0; i < kW; ++i) {
      const Eigen::Vector2d d = Eigen::Vector2d(i + 0.5, j + 0.5) - mu;
      double al = std::min(0.99, o * std::exp(-0.5 * d.dot(inv * d)));
      if (std::abs(d.x()) > hx || std::abs(d.y()) > hy || al < 1.0 / 255) al = 0;
      covered += al > 0;
      EXPECT_NEAR(im.alpha[pix(i, j)], al, 1e-12);
      if (al > 0) {
        EXPECT_NEAR(im.depth[pix(i, j)], p.z(), 1e-12);
      }
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(im.rgb[3 * pix(i, j) + c], al * (kShC0 * sp.dc[c] + 0.5), 1e-12);
    }
  EXPECT_GT(covered, 5);
}

TEST(ReferenceRenderer, DegreeOneShFollowsWorldViewDirection) {
  // Camera rotated 180 degrees about its z axis and 3 units back: world x maps to image
  // -x, so the world-frame direction (not the camera-frame one) must set the colour.
  Camera cam = testCamera(16, 12);
  cam.R = Eigen::Vector3d(-1, -1, 1).asDiagonal();
  cam.t = {0, 0, 3};
  RasterSettings s;
  s.sh_degree = 1;
  // Means chosen to project onto pixel centres (8.5, 11.5) and (23.5, 11.5), where
  // G = 1 and alpha = min(0.99, sigmoid(30)) = 0.99 whatever Sigma2D is.
  std::vector<Spec> specs(2);
  specs[0].mean = {0.75, 0.05, 0};
  specs[1].mean = {-0.75, 0.05, 0};
  for (Spec& sp : specs) {
    sp.scale = {0.05, 0.05, 0.05};
    sp.opacity_logit = 30;
  }
  GaussiansD g = makeModel(specs, 1);
  const double coef[3] = {1.0, -1.0, 0.5};
  for (int i = 0; i < 2; ++i)
    for (int c = 0; c < 3; ++c) g.sh[(i * 4 + 3) * 3 + c] = coef[c];  // k = 3: -C1 x
  const ReferenceImage im = referenceRender(g, cam, s);
  s.sh_degree = 0;
  const ReferenceImage im0 = referenceRender(g, cam, s);
  const Eigen::Vector3d centre(0, 0, -3);
  const int columns[2] = {8, 23};  // camera frame (-x, -y, z + 3): u = -10 x + 16
  for (int i = 0; i < 2; ++i) {
    ASSERT_EQ(im.visible[i], 1);
    const Eigen::Vector3d d = (specs[i].mean - centre).normalized();
    const std::size_t p = pix(columns[i], 11);
    EXPECT_EQ(im.contributors[p], 1);
    for (int c = 0; c < 3; ++c) {
      const double col = std::max(0.0, -sh_constants::C1 * d.x() * coef[c] + 0.5);
      EXPECT_NEAR(im.rgb[3 * p + c], 0.99 * col, 1e-12) << i << " " << c;
      EXPECT_NEAR(im0.rgb[3 * p + c], 0.99 * 0.5, 1e-12);
    }
  }
  // The sign flips with the direction's world x: red is darker on the +x side, which is
  // the image's left half for this camera.
  EXPECT_LT(im.rgb[3 * pix(8, 11)], 0.99 * 0.5);
  EXPECT_GT(im.rgb[3 * pix(23, 11)], 0.99 * 0.5);
  EXPECT_GT(im.rgb[3 * pix(8, 11) + 1], 0.99 * 0.5);
}

TEST(ReferenceRenderer, DepthIsCameraZWhereCovered) {
  const Camera cam = testCamera();
  RasterSettings s;
  Spec sp;
  sp.mean = {0.1, -0.05, 2};  // camera z = 2, off axis
  sp.scale = {0.1, 0.1, 0.1};
  sp.opacity_logit = 5;
  const ReferenceImage im = referenceRender(makeModel({sp}), cam, s);
  int covered = 0, empty = 0;
  for (std::size_t p = 0; p < im.alpha.size(); ++p) {
    if (im.contributors[p] > 0) {
      ++covered;
      EXPECT_NEAR(im.depth[p], 2.0, 1e-12);
    } else {
      ++empty;
      EXPECT_EQ(im.alpha[p], 0.0);
      EXPECT_EQ(im.depth[p], 0.0);
    }
  }
  EXPECT_GT(covered, 10);
  EXPECT_GT(empty, 10);
}

TEST(ReferenceRenderer, ZeroQuaternionIsIdentityAndNormIsIgnored) {
  const Camera cam = testCamera();
  RasterSettings s;
  Spec sp{.mean = {0.1, 0.05, 2}, .scale = {0.2, 0.05, 0.1}, .opacity_logit = 1, .dc = {1, 0.5, 0}};
  const ReferenceImage id = referenceRender(makeModel({sp}), cam, s);
  sp.quat = {0, 0, 0, 0};
  const ReferenceImage zero = referenceRender(makeModel({sp}), cam, s);
  EXPECT_EQ(id.rgb, zero.rgb);
  EXPECT_EQ(id.radii, zero.radii);
  sp.quat = {1e-30, 0, 0, 0};
  const ReferenceImage tiny = referenceRender(makeModel({sp}), cam, s);
  EXPECT_EQ(id.rgb, tiny.rgb);
  // A non-unit quaternion renders as its normalisation.
  sp.quat = {0.9, 0.1, -0.2, 0.3};
  const ReferenceImage q1 = referenceRender(makeModel({sp}), cam, s);
  sp.quat *= 7.0;
  const ReferenceImage q7 = referenceRender(makeModel({sp}), cam, s);
  for (std::size_t k = 0; k < q1.rgb.size(); ++k) EXPECT_NEAR(q1.rgb[k], q7.rgb[k], 1e-12);
  EXPECT_NE(q1.rgb, id.rgb);
}

TEST(ReferenceRenderer, ExtremeInputsStayFinite) {
  const double scales[] = {1e-6, 1e-3, 1.0, 1e4};
  const double logits[] = {-30, -5, 0, 5, 30};
  std::vector<Spec> specs;
  const double near = RasterSettings{}.near_plane;
  const Eigen::Vector3d means[] = {{0, 0, 2},
                                   {0, 0, near},
                                   {0, 0, -1},
                                   {0, 0, 0},
                                   {-15.3 / 15, -11.7 / 15, 2},  // exactly on the top-left image corner
                                   {16.7 / 15, 12.3 / 15, 2},    // exactly on the bottom-right corner
                                   {-15.3 / 15, 0, 2},
                                   {0.3, 0.2, 1e-5},
                                   {1e3, -1e3, 1e3}};
  for (const auto& m : means)
    for (double sa : scales)
      for (double lg : logits) {
        Spec sp;
        sp.mean = m;
        sp.scale = {sa, sa, sa};
        sp.opacity_logit = lg;
        sp.dc = {1, -1, 0.5};
        specs.push_back(sp);
        sp.scale = {1e4, 1e-6, 1e-6};  // needle
        sp.quat = {std::cos(0.3), 0, std::sin(0.3), 0.1};
        specs.push_back(sp);
        sp.quat = {0, 0, 0, 0};
        sp.scale = {sa, 1e-6, sa};
        specs.push_back(sp);
      }
  const GaussiansD g = makeModel(specs);
  for (ExtentRule rule : {ExtentRule::kOpacityAware, ExtentRule::kThreeSigma}) {
    RasterSettings s;
    s.extent = rule;
    s.background = {0.3f, 0.6f, 0.9f};
    const ReferenceImage im = referenceRender(g, testCamera(), s);
    EXPECT_TRUE(allFiniteRender(im));
    // 1x1 image.
    Camera one;
    one.K = Intrinsics{1, 1, 1.0, 1.0, 0.5, 0.5};
    const ReferenceImage tiny = referenceRender(g, one, s);
    ASSERT_EQ(tiny.rgb.size(), 3u);
    EXPECT_TRUE(allFiniteRender(tiny));
    EXPECT_GT(tiny.contributors[0], 0);
    // Each extreme on its own, too (no neighbour to hide behind).
    for (std::size_t k = 0; k < specs.size(); ++k) {
      const ReferenceImage single = referenceRender(makeModel({specs[k]}), testCamera(), s);
      ASSERT_TRUE(allFiniteRender(single)) << k;
      if (specs[k].mean.z() < near) {
        EXPECT_EQ(single.visible[0], 0) << k;
      }
    }
  }
}

TEST(ReferenceRenderer, RejectsMismatchedInputs) {
  const Camera cam = testCamera();
  RasterSettings s;
  GaussiansD g = makeModel({Spec{}});
  std::vector<std::uint8_t> mask(2, 1);
  EXPECT_THROW(referenceRender(g, cam, s, mask), std::invalid_argument);
  s.sh_degree = 1;
  EXPECT_THROW(referenceRender(g, cam, s), std::invalid_argument);
  s.sh_degree = 0;
  g.means.pop_back();
  EXPECT_THROW(referenceRender(g, cam, s), std::invalid_argument);
}
