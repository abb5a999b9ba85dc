// The fast tiled path against the slow per-pixel reference (written independently from
// the contract in splat/rasterize.h): images, per-pixel and per-Gaussian outputs, and
// the fast path's analytic gradients against finite differences of the reference.
#include <gtest/gtest.h>

#include <random>

#include "raster_test_scenes.h"
#include "splat/raster/rasterize_detail.h"
#include "splat/raster/reference_renderer.h"

using namespace saresgs;

// A scene of the parameterised test (a type with linkage: the fixture derives from it).
struct FastVsReferenceCase {
  int gaussians, sh_degree, width, height;
  ExtentRule rule;
  std::uint64_t seed;
};

class FastVsReference : public ::testing::TestWithParam<FastVsReferenceCase> {};

TEST_P(FastVsReference, ImagesAndPerGaussianOutputsAgree) {
  const FastVsReferenceCase c = GetParam();
  const Camera cam = test::smallCamera(c.width, c.height);
  const GaussiansD gd = test::randomScene<double>(c.gaussians, c.sh_degree, c.seed, 1.2);
  RasterSettings s;
  s.sh_degree = c.sh_degree;
  s.extent = c.rule;
  s.background = {0.25f, 0.5f, 0.75f};
  std::vector<std::uint8_t> mask(gd.size(), 1);
  for (std::size_t i = 1; i < gd.size(); i += 5) mask[i] = 0;
  for (bool masked : {false, true}) {
    SCOPED_TRACE(masked ? "masked" : "full");
    const std::span<const std::uint8_t> m =
        masked ? std::span<const std::uint8_t>(mask) : std::span<const std::uint8_t>();
    const ReferenceImage ref = referenceRender(gd, cam, s, m);
    const auto fast = rasterizeT(gd, cam, s, m);
    for (const auto& [name, kernels] : test::runnableKernels()) {
      SCOPED_TRACE(name);
      RasterSettings sk = s;
      sk.execution.kernels = kernels;
      const auto fastf = rasterizeT(gd.cast<float>(), cam, sk, m);
      // Float fast path: to float tolerance (a pixel may differ by one borderline
      // contribution, see the reference's notes on the 1e-4 stop rule).
      int off = 0;
      for (std::size_t k = 0; k < ref.rgb.size(); ++k) off += std::abs(fastf.rgb[k] - ref.rgb[k]) > 1e-4;
      EXPECT_LE(off, static_cast<int>(ref.rgb.size() / 1000)) << off << " channels off by > 1e-4";
    }
    // Double fast path: the same arithmetic up to summation order.
    for (std::size_t k = 0; k < ref.rgb.size(); ++k) ASSERT_NEAR(fast.rgb[k], ref.rgb[k], 1e-9);
    for (std::size_t k = 0; k < ref.alpha.size(); ++k) {
      ASSERT_NEAR(fast.alpha[k], ref.alpha[k], 1e-9);
      ASSERT_NEAR(fast.depth[k], ref.depth[k], 1e-7 * (1 + ref.depth[k]));
      ASSERT_EQ(fast.contributors[k], ref.contributors[k]) << "pixel " << k;
    }
    for (std::size_t i = 0; i < gd.size(); ++i) {
      ASSERT_EQ(fast.visible[i], ref.visible[i]) << "Gaussian " << i;
      ASSERT_NEAR(fast.radii[i], ref.radii[i], 1e-9 * (1 + ref.radii[i]));
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, FastVsReference,
                         ::testing::Values(FastVsReferenceCase{40, 0, 40, 30, ExtentRule::kOpacityAware, 1},
                                           FastVsReferenceCase{80, 3, 48, 40, ExtentRule::kOpacityAware, 2},
                                           FastVsReferenceCase{80, 1, 33, 17, ExtentRule::kThreeSigma, 3},
                                           FastVsReferenceCase{150, 2, 64, 48, ExtentRule::kOpacityAware, 4},
                                           FastVsReferenceCase{5, 0, 1, 1, ExtentRule::kOpacityAware, 5}));

TEST(FastVsReference, AnalyticGradientsMatchFiniteDifferencesOfTheReference) {
  const Camera cam = test::smallCamera(20, 16);
  for (int sh_degree : {0, 3}) {
    SCOPED_TRACE(sh_degree);
    GaussiansD g = test::randomScene<double>(6, sh_degree, 40 + sh_degree);
    RasterSettings s;
    s.sh_degree = sh_degree;
    s.background = {0.6f, 0.1f, 0.3f};
    std::mt19937_64 rng(7);
    std::normal_distribution<double> nd(0, 1);
    std::vector<double> w(20 * 16 * 3);
    for (auto& v : w) v = nd(rng);
    const auto fwd = rasterizeT(g, cam, s);
    GaussiansD grad = g.zerosLike();
    rasterizeBackwardT(g, cam, s, fwd, w.data(), grad);
    auto loss = [&] {
      const ReferenceImage r = referenceRender(g, cam, s);
      double l = 0;
      for (std::size_t k = 0; k < w.size(); ++k) l += w[k] * r.rgb[k];
      return l;
    };
    test::GradCheck gc;
    test::checkGradients(g, grad, loss, gc);
    EXPECT_EQ(gc.bad, 0);
    EXPECT_GT(gc.checked, 80);
    EXPECT_LE(gc.kinks, gc.checked / 20);
  }
}

// Extreme lenses and principal points (issue 25): fields of view from 1 to 150 degrees,
// the principal point at the centre, at a corner and outside the image, and images from
// 8x6 to 2048x1536. The camera backs off so the scene fills the view, which at 150 degrees
// puts it among the Gaussians (some behind it, some within the near plane). Every output
// is finite, the double fast path equals the reference, and the float one agrees with it
// to float tolerance; with the principal point inside, the scene is seen.
TEST(FastVsReference, ExtremeFieldsOfViewPrincipalPointsAndImageSizes) {
  const GaussiansD gd = test::randomScene<double>(30, 1, 77, 1.0);
  RasterSettings s;
  s.sh_degree = 1;
  s.background = {0.25f, 0.5f, 0.75f};
  struct Lens {
    double fov_deg;
    int w, h;
    double cx_rel, cy_rel;
  };
  std::vector<Lens> lenses;
  for (double fov : {1.0, 10.0, 60.0, 120.0, 150.0})
    for (auto [cx, cy] : {std::pair{0.5, 0.5}, std::pair{0.0, 0.0}, std::pair{1.5, -0.5}})
      lenses.push_back({fov, 40, 30, cx, cy});
  lenses.push_back({60.0, 8, 6, 0.5, 0.5});
  lenses.push_back({60.0, 2048, 1536, 0.5, 0.5});
  for (const Lens& L : lenses) {
    SCOPED_TRACE("fov " + std::to_string(L.fov_deg) + " " + std::to_string(L.w) + "x" + std::to_string(L.h) +
                 " principal point (" + std::to_string(L.cx_rel) + ", " + std::to_string(L.cy_rel) + ") of the image");
    Intrinsics K;
    K.width = L.w;
    K.height = L.h;
    const double half = 0.5 * L.fov_deg * M_PI / 180.0;
    K.fx = K.fy = 0.5 * L.w / std::tan(half);
    K.cx = L.cx_rel * L.w;
    K.cy = L.cy_rel * L.h;
    // The scene's 1-sigma radius (about 1) fills the view's half width.
    const double dist = 1.0 / std::tan(half);
    const Camera cam =
        Camera::lookAt(K, Eigen::Vector3d(0.1, -dist, 0.2), Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ());
    const ReferenceImage ref = referenceRender(gd, cam, s);
    const auto fast = rasterizeT(gd, cam, s);
    for (std::size_t k = 0; k < ref.rgb.size(); ++k) ASSERT_NEAR(fast.rgb[k], ref.rgb[k], 1e-9) << k;
    for (std::size_t k = 0; k < ref.alpha.size(); ++k) ASSERT_EQ(fast.contributors[k], ref.contributors[k]) << k;
    for (std::size_t i = 0; i < gd.size(); ++i) ASSERT_EQ(fast.visible[i], ref.visible[i]) << "Gaussian " << i;
    const auto fastf = rasterizeT(gd.cast<float>(), cam, s);
    int off = 0;
    for (std::size_t k = 0; k < ref.rgb.size(); ++k) {
      ASSERT_TRUE(std::isfinite(fastf.rgb[k]));
      off += std::abs(fastf.rgb[k] - ref.rgb[k]) > 1e-4;
    }
    EXPECT_LE(off, static_cast<int>(ref.rgb.size() / 1000) + 1) << off << " channels off by > 1e-4";
    if (L.cx_rel == 0.5) {
      double max_alpha = 0;
      for (double a : ref.alpha) max_alpha = std::max(max_alpha, a);
      EXPECT_GT(max_alpha, 0.3) << "the scene should be in view";
    }
    // Gradients and Fisher information stay finite.
    std::vector<float> w(fastf.rgb.size(), 1.0f);
    Gaussians grad = gd.cast<float>().zerosLike(), sq = gd.cast<float>().zerosLike();
    rasterizeBackwardT(gd.cast<float>(), cam, s, fastf, w.data(), grad);
    rasterizeSquaredGradientsT(gd.cast<float>(), cam, s, fastf, sq);
    for (const Gaussians* x : {&grad, &sq})
      x->forEachArray([](const std::vector<float>& a, std::size_t) {
        for (float v : a) ASSERT_TRUE(std::isfinite(v));
      });
  }
}
