// FisherRF's diagonal information against finite differences, and its score's
// behaviour: a duplicate of a train view is worth less than a view of unseen Gaussians.
#include <gtest/gtest.h>

#include <cmath>

#include "raster_test_scenes.h"
#include "splat/fisher.h"
#include "splat/fisher_detail.h"

namespace saresgs {
namespace {

// Sum over pixels of the squared central difference of (R + G + B) per parameter.
GaussiansD finiteDifferenceInformation(GaussiansD g, const Camera& cam, const RasterSettings& s) {
  GaussiansD H = g.zerosLike();
  auto sumRgb = [&](const GaussiansD& m) {
    const auto out = rasterizeT(m, cam, s);
    std::vector<double> v(out.rgb.size() / 3);
    for (std::size_t p = 0; p < v.size(); ++p) v[p] = out.rgb[3 * p] + out.rgb[3 * p + 1] + out.rgb[3 * p + 2];
    return v;
  };
  auto fill = [&](std::vector<double>& param, std::vector<double>& h_out) {
    for (std::size_t k = 0; k < param.size(); ++k) {
      const double x0 = param[k], h = 1e-6 * std::max(1.0, std::abs(x0));
      param[k] = x0 + h;
      const auto a = sumRgb(g);
      param[k] = x0 - h;
      const auto b = sumRgb(g);
      param[k] = x0;
      double acc = 0;
      for (std::size_t p = 0; p < a.size(); ++p) acc += std::pow((a[p] - b[p]) / (2 * h), 2);
      h_out[k] = acc;
    }
  };
  fill(g.means, H.means);
  fill(g.log_scales, H.log_scales);
  fill(g.opacities, H.opacities);
  fill(g.sh, H.sh);
  return H;
}

TEST(Fisher, ScoreEqualsSumOfSquaredFiniteDifferenceGradients) {
  const GaussiansD g = test::randomScene<double>(5, 1, 21, 0.6);
  RasterSettings s;
  s.sh_degree = 1;
  s.background = {0.2f, 0.4f, 0.1f};
  const Camera train = test::smallCamera(16, 14);
  Intrinsics K = train.K;
  const Camera cand = Camera::lookAt(K, Eigen::Vector3d(2.5, -2.0, 0.6), Eigen::Vector3d(0, 0, 0), Eigen::Vector3d::UnitZ());
  GaussiansD Ht = g.zerosLike(), Hv = g.zerosLike();
  addViewInformationT(g, train, s, Ht);
  addViewInformationT(g, cand, s, Hv);
  const GaussiansD Ht_fd = finiteDifferenceInformation(g, train, s), Hv_fd = finiteDifferenceInformation(g, cand, s);
  for (double lambda : {1e-6, 1e-2}) {
    const double analytic = fisherScore(Hv, Ht, lambda), fd = fisherScore(Hv_fd, Ht_fd, lambda);
    EXPECT_GT(analytic, 0);
    EXPECT_NEAR(analytic, fd, 1e-4 * std::abs(fd)) << lambda;
  }
  // Entry-wise too (the score could hide compensating errors).
  for (std::size_t k = 0; k < Hv.means.size(); ++k) EXPECT_NEAR(Hv.means[k], Hv_fd.means[k], 1e-4 * (1 + Hv_fd.means[k]));
  for (std::size_t k = 0; k < Hv.sh.size(); ++k) EXPECT_NEAR(Hv.sh[k], Hv_fd.sh[k], 1e-4 * (1 + Hv_fd.sh[k]));
}

TEST(Fisher, DuplicateOfATrainViewScoresBelowAViewOfUnseenGaussians) {
  // Two clusters: the train camera sees only the left one; one candidate duplicates it,
  // the other looks at the right cluster.
  Gaussians g = test::randomScene<float>(24, 0, 5, 0.25);
  for (std::size_t i = 0; i < g.size(); ++i) g.means[3 * i] += (i % 2 ? 3.0f : -3.0f);
  RasterSettings s;
  Intrinsics K;
  K.width = 32;
  K.height = 24;
  K.fx = K.fy = 30;
  K.cx = 16;
  K.cy = 12;
  const Camera left = Camera::lookAt(K, Eigen::Vector3d(-3, -3, 0), Eigen::Vector3d(-3, 0, 0), Eigen::Vector3d::UnitZ());
  const Camera right = Camera::lookAt(K, Eigen::Vector3d(3, -3, 0), Eigen::Vector3d(3, 0, 0), Eigen::Vector3d::UnitZ());
  Gaussians Ht = g.zerosLike(), Hdup = g.zerosLike(), Hnew = g.zerosLike();
  addViewInformationT(g, left, s, Ht);
  addViewInformationT(g, left, s, Hdup);
  addViewInformationT(g, right, s, Hnew);
  const double dup = fisherScore(Hdup, Ht, 1e-6), fresh = fisherScore(Hnew, Ht, 1e-6);
  EXPECT_GT(fresh, 100 * dup) << dup << " vs " << fresh;
  // The duplicate's score is bounded by the number of informative parameters (each
  // term H / (H + lambda) < 1).
  std::size_t informative = 0;
  Hdup.forEachArray([&](const std::vector<float>& a, std::size_t) {
    for (float x : a) informative += x > 0;
  });
  EXPECT_LE(dup, static_cast<double>(informative));
}

TEST(Fisher, GeometryVarianceAndScalarColorRender) {
  Gaussians g = test::randomScene<float>(6, 2, 3);
  Gaussians H = g.zerosLike();
  H.means.assign(H.means.size(), 1.0f);
  H.log_scales.assign(H.log_scales.size(), 3.0f);
  const auto var = gaussianGeometryVariance(H, 0.0);
  for (float v : var) EXPECT_NEAR(v, 3.0 + 1.0, 1e-5);
  const Gaussians c = withScalarColor(g, var);
  EXPECT_EQ(c.max_sh_degree, 0);
  EXPECT_NEAR(c.sh[4] * kShC0 + 0.5, 4.0, 1e-5);
  EXPECT_THROW(withScalarColor(g, {1.0f}), std::invalid_argument);
}

}  // namespace
}  // namespace saresgs
