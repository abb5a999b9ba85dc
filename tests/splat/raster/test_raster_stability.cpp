// Stiff and extreme cases: no NaN or Inf may escape into images or gradients.
#include <gtest/gtest.h>

#include <cmath>

#include "common/pinhole.h"
#include "raster_test_scenes.h"
#include "splat/raster/rasterize_detail.h"

using namespace saresgs;

namespace {

template <typename V>
bool allFinite(const V& v) {
  for (auto x : v)
    if (!std::isfinite(static_cast<double>(x))) return false;
  return true;
}

// Renders (float, the product path), back-propagates a dense loss and the squared
// gradients, and checks every output is finite. Returns the forward output.
RenderOutputT<float> renderChecked(const Gaussians& g, const Camera& cam, int sh_degree = 0) {
  RasterSettings s;
  s.sh_degree = sh_degree;
  s.background = {0.1f, 0.2f, 0.3f};
  const auto r = rasterizeT(g, cam, s);
  EXPECT_TRUE(allFinite(r.rgb));
  EXPECT_TRUE(allFinite(r.alpha));
  EXPECT_TRUE(allFinite(r.depth));
  EXPECT_TRUE(allFinite(r.radii));
  std::vector<float> w(r.rgb.size(), 1.0f);
  Gaussians grad = g.zerosLike();
  std::vector<float> g2d(2 * g.size(), 0.0f);
  rasterizeBackwardT(g, cam, s, r, w.data(), grad, &g2d);
  grad.forEachArray([](const std::vector<float>& a, std::size_t) { EXPECT_TRUE(allFinite(a)); });
  EXPECT_TRUE(allFinite(g2d));
  Gaussians sq = g.zerosLike();
  rasterizeSquaredGradientsT(g, cam, s, r, sq);
  sq.forEachArray([](const std::vector<float>& a, std::size_t) { EXPECT_TRUE(allFinite(a)); });
  return r;
}

}  // namespace

TEST(RasterStability, ScalesFromTinyToHuge) {
  const Camera cam = test::smallCamera(32, 24);
  const double extent = 3.0;  // the test camera's distance to the scene
  for (double rel : {1e-6, 1e-4, 1e-2, 1.0, 1e2, 1e4}) {
    SCOPED_TRACE(rel);
    const auto r = renderChecked(test::oneGaussian(Eigen::Vector3d(0.1, 0.0, 0.05), rel * extent), cam);
    if (rel >= 1.0) {
      EXPECT_GT(r.alpha[12 * 32 + 16], 0.0f);  // a big Gaussian covers the centre
    }
  }
  // Anisotropic: one axis tiny, one huge.
  Gaussians g = test::oneGaussian(Eigen::Vector3d::Zero(), 1.0);
  g.log_scales = {std::log(1e-6f * 3), std::log(1e4f * 3), 0.0f};
  renderChecked(g, cam);
}

TEST(RasterStability, OpacityLogitsOfPlusMinusThirty) {
  const Camera cam = test::smallCamera(32, 24);
  Gaussians g = test::randomScene<double>(20, 1, 30).cast<float>();
  for (std::size_t i = 0; i < g.size(); ++i) g.opacities[i] = (i % 2) ? 30.0f : -30.0f;
  const auto r = renderChecked(g, cam, 1);
  for (std::size_t i = 0; i < g.size(); i += 2) EXPECT_EQ(r.visible[i], 0);  // o ~ 1e-13 is culled
}

TEST(RasterStability, ZeroQuaternionIsTheIdentity) {
  const Camera cam = test::smallCamera(32, 24);
  Gaussians a = test::oneGaussian(Eigen::Vector3d(0.1, 0, 0), 0.3);
  a.log_scales = {std::log(0.5f), std::log(0.1f), std::log(0.2f)};
  Gaussians z = a;
  z.rotations = {0, 0, 0, 0};
  const auto ra = renderChecked(a, cam), rz = renderChecked(z, cam);
  EXPECT_TRUE(ra.rgb == rz.rgb);
}

TEST(RasterStability, NearPlaneBehindTheCameraAndOnTheBorders) {
  const Camera cam = test::smallCamera(32, 24);
  // In order: at the near plane, before it, behind the camera, on the left border, on the
  // bottom-right corner, at the camera centre.
  const Gaussians g = test::nearPlaneAndBorderScene(cam, RasterSettings{});
  const auto r = renderChecked(g, cam);
  EXPECT_EQ(r.visible[1], 0);
  EXPECT_EQ(r.visible[2], 0);
  EXPECT_EQ(r.visible[5], 0);
  EXPECT_EQ(r.visible[3], 1);
  EXPECT_EQ(r.visible[4], 1);
}

TEST(RasterStability, OneByOneAndVeryWideImages) {
  for (auto [w, h] : {std::pair{1, 1}, std::pair{4096, 8}, std::pair{7, 4096}}) {
    SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h));
    const Intrinsics K = test::pinhole(w, h, 1.2 * std::max(w, h));
    const Camera cam = Camera::lookAt(K, Eigen::Vector3d(0, -3, 0), Eigen::Vector3d::Zero());
    const Gaussians g = test::randomScene<double>(50, 2, 31).cast<float>();
    const auto r = renderChecked(g, cam, 2);
    EXPECT_EQ(r.rgb.size(), static_cast<std::size_t>(w) * h * 3);
  }
}

TEST(RasterStability, EmptyModelAndDegenerateCamera) {
  const Camera cam = test::smallCamera(16, 16);
  Gaussians none;
  const auto r = renderChecked(none, cam);
  EXPECT_FLOAT_EQ(r.rgb[0], 0.1f);  // background
  // A camera with a huge focal length (near-zero field of view) still gives finite output.
  Camera narrow = cam;
  narrow.K.fx = narrow.K.fy = 1e9;
  renderChecked(test::randomScene<double>(10, 0, 32).cast<float>(), narrow);
}
