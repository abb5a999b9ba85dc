// FisherRF's diagonal information against finite differences, and its score's
// behaviour: a duplicate of a train view is worth less than a view of unseen Gaussians.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "common/pinhole.h"
#include "raster_test_scenes.h"
#include "splat/fisher.h"
#include "splat/fisher_detail.h"
#include "splat/raster/projection.h"
#include "tests/splat/gaussians_bits.h"

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
  const Camera cand =
      Camera::lookAt(K, Eigen::Vector3d(2.5, -2.0, 0.6), Eigen::Vector3d(0, 0, 0), Eigen::Vector3d::UnitZ());
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
  for (std::size_t k = 0; k < Hv.means.size(); ++k)
    EXPECT_NEAR(Hv.means[k], Hv_fd.means[k], 1e-4 * (1 + Hv_fd.means[k]));
  for (std::size_t k = 0; k < Hv.sh.size(); ++k) EXPECT_NEAR(Hv.sh[k], Hv_fd.sh[k], 1e-4 * (1 + Hv_fd.sh[k]));
}

// The float squared-gradient pass (SIMD tile moments, raster_kernels.h) against the
// double per-pixel walk, the reference, on the same scene and camera.
struct FisherCase {
  std::string name;
  Gaussians g;
  Camera cam;
  int sh_degree = 0;
  std::array<float, 3> background{0, 0, 0};
};

// Random scenes of every SH degree with and without a background, and the stiff cases of
// test_raster_stability.cpp: scales from 1e-6 to 1e4 of the scene's distance (and both at
// once), opacity logits of +-30, Gaussians at and before the near plane, behind the
// camera, on the borders and at the camera centre.
std::vector<FisherCase> fisherCases() {
  std::vector<FisherCase> cases;
  const Camera cam = test::smallCamera(64, 48);
  for (int sh = 0; sh <= 3; ++sh)
    cases.push_back({"random sh" + std::to_string(sh), test::randomScene<double>(120, sh, 50 + sh, 1.2).cast<float>(),
                     cam, sh, sh % 2 ? std::array<float, 3>{0.3f, 0.1f, 0.6f} : std::array<float, 3>{0, 0, 0}});
  cases.push_back({"dense",
                   test::randomScene<double>(400, 1, 60, 0.7).cast<float>(),
                   test::smallCamera(50, 37),
                   1,
                   {0.2f, 0.2f, 0.2f}});
  {
    // Large Gaussians on a larger view: offsets from the 2D mean of a hundred pixels and
    // more, where the moments' powers of dx, dy (up to four) are largest.
    Gaussians big = test::randomScene<double>(40, 2, 65, 1.0).cast<float>();
    for (float& v : big.log_scales) v += 1.5f;
    cases.push_back({"large Gaussians 256x192", big, test::smallCamera(256, 192), 2, {0.1f, 0.1f, 0.1f}});
  }
  const Camera small = test::smallCamera(32, 24);
  for (double rel : {1e-6, 1e-4, 1e-2, 1.0, 1e2, 1e4})
    cases.push_back({"scale " + std::to_string(rel),
                     test::oneGaussian(Eigen::Vector3d(0.1, 0.0, 0.05), rel * 3.0),
                     small,
                     0,
                     {0.1f, 0.2f, 0.3f}});
  Gaussians aniso = test::oneGaussian(Eigen::Vector3d::Zero(), 1.0);
  aniso.log_scales = {std::log(1e-6f * 3), std::log(1e4f * 3), 0.0f};
  cases.push_back({"anisotropic 1e-6 / 1e4", aniso, small, 0, {0.1f, 0.2f, 0.3f}});
  Gaussians logits = test::randomScene<double>(20, 1, 30).cast<float>();
  for (std::size_t i = 0; i < logits.size(); ++i) logits.opacities[i] = (i % 2) ? 30.0f : -30.0f;
  cases.push_back({"logits +-30", logits, small, 1, {0.1f, 0.2f, 0.3f}});
  cases.push_back({"near plane, behind, borders",
                   test::nearPlaneAndBorderScene(small, RasterSettings{}),
                   small,
                   0,
                   {0.1f, 0.2f, 0.3f}});
  return cases;
}

Gaussians floatInformation(const Gaussians& g, const Camera& cam, RasterSettings s, RasterKernels kernels,
                           int threads) {
  s.execution.kernels = kernels;
  s.execution.threads = threads;
  Gaussians H = g.zerosLike();
  addViewInformationT(g, cam, s, H);
  return H;
}

TEST(Fisher, FloatPassEqualsTheDoubleReferenceOnEveryKernelSet) {
  for (const FisherCase& fc : fisherCases()) {
    SCOPED_TRACE(fc.name);
    RasterSettings s;
    s.sh_degree = fc.sh_degree;
    s.background = fc.background;
    const GaussiansD gd = fc.g.cast<double>();
    GaussiansD Hd = gd.zerosLike();
    addViewInformationT(gd, fc.cam, s, Hd);
    // The float render itself drifts from double where float cannot represent the
    // projection (a 1e-6 by 1e4 covariance seen along its long axis). There the float
    // pixel walk, with the same float inputs, is the reference for what does not go
    // through the projection's Jacobian (opacities, SH); the means and log-scales are
    // float noise in any float evaluation (the walk, the fast pass and double disagree
    // by factors), so only their finiteness and sign are checked.
    const auto rf = rasterizeT(fc.g, fc.cam, s);
    const auto rd = rasterizeT(gd, fc.cam, s);
    double render_drift = 0;
    for (std::size_t k = 0; k < rf.rgb.size(); ++k)
      render_drift = std::max(render_drift, std::abs(rf.rgb[k] - rd.rgb[k]));
    const bool drift = render_drift > 1e-4;
    if (drift) {
      Gaussians Hw = fc.g.zerosLike();
      rasterizeSquaredGradientsWalkT(fc.g, fc.cam, s, rf, Hw);
      Hd = Hw.cast<double>();
    }
    EXPECT_EQ(drift, fc.name == "anisotropic 1e-6 / 1e4") << render_drift;
    for (const auto& [name, kernels] : test::runnableFisherKernels()) {
      SCOPED_TRACE(name);
      const Gaussians Hf = floatInformation(fc.g, fc.cam, s, kernels, 0);
      // Per entry to float precision, relative to the entry and, for entries near zero,
      // to the largest of its array (float rounds the render's own sums).
      auto compare = [&](const std::vector<double>& d, const std::vector<float>& f, const char* what,
                         bool values = true) {
        double scale = 0;
        for (double v : d) scale = std::max(scale, std::abs(v));
        for (std::size_t k = 0; k < d.size(); ++k) {
          ASSERT_TRUE(std::isfinite(f[k])) << what << "[" << k << "]";
          ASSERT_GE(f[k], 0.0f) << what << "[" << k << "]";
          if (values) {
            EXPECT_NEAR(f[k], d[k], 3e-4 * std::abs(d[k]) + 3e-6 * scale + 1e-12) << what << "[" << k << "]";
          }
        }
      };
      compare(Hd.means, Hf.means, "means", !drift);
      compare(Hd.log_scales, Hf.log_scales, "log_scales", !drift);
      compare(Hd.opacities, Hf.opacities, "opacities");
      compare(Hd.sh, Hf.sh, "sh");
      for (float v : Hf.rotations) EXPECT_EQ(v, 0.0f);
    }
  }
}

// The avx512 kernel set's Fisher walk (one pass over 32 registers) gives the avx2
// walk's information bit for bit, on every case above (backgrounds, stiff scales, the
// near plane, large offsets), with and without threads.
TEST(Fisher, Avx512WalkEqualsAvx2BitForBit) {
  if (!rasterCpuHasAvx512()) GTEST_SKIP() << "no AVX-512F and AVX-512VL on this CPU (the avx512 set cannot run here)";
  int nonzero = 0;
  for (const FisherCase& fc : fisherCases()) {
    SCOPED_TRACE(fc.name);
    RasterSettings s;
    s.sh_degree = fc.sh_degree;
    s.background = fc.background;
    for (int threads : {1, 0}) {
      const Gaussians a = floatInformation(fc.g, fc.cam, s, RasterKernels::kAvx2, threads);
      const Gaussians b = floatInformation(fc.g, fc.cam, s, RasterKernels::kAvx512, threads);
      auto same = [](const std::vector<float>& x, const std::vector<float>& y, const char* what) {
        ASSERT_EQ(x.size(), y.size()) << what;
        for (std::size_t k = 0; k < x.size(); ++k)
          ASSERT_EQ(std::bit_cast<std::uint32_t>(x[k]), std::bit_cast<std::uint32_t>(y[k]))
              << what << "[" << k << "]: avx2 " << x[k] << ", avx512 " << y[k];
      };
      test::forEachArrayPair(a, b, same);
      for (float v : a.means) nonzero += v != 0.0f;
    }
  }
  EXPECT_GT(nonzero, 1000);  // the cases carry information to compare
}

TEST(Fisher, JacobianEqualsProjectBackwardWithUnitInputs) {
  // projectJacobian's rows (the conic ones in closed form) against projectBackward run
  // once per input, in double, on anisotropic rotated Gaussians at every SH degree.
  const Camera cam = test::smallCamera(64, 48);
  for (int sh = 0; sh <= 3; ++sh) {
    SCOPED_TRACE(sh);
    GaussiansD g = test::randomScene<double>(60, sh, 80 + sh, 1.2);
    for (std::size_t i = 0; i < g.size(); i += 7) g.log_scales[3 * i] = 70.0;  // clamped scale: no gradient
    RasterSettings s;
    s.sh_degree = sh;
    const projection::CameraT<double> ct(cam, double(s.guard_band));
    int checked = 0;
    for (std::size_t i = 0; i < g.size(); ++i) {
      const projection::Projected<double> P = projection::project(g, i, ct, s);
      if (!P.visible) continue;
      ++checked;
      const auto f = projection::backwardFrame(g, i, ct, s);
      double J[6][6];
      projection::projectJacobian(g, i, ct, s, P, f, J);
      for (int r = 0; r < 6; ++r) {
        projection::ProjectedGrad<double> dP;
        if (r < 2)
          dP.mean2d[r] = 1;
        else if (r < 5)
          dP.conic[r - 2] = 1;
        else
          dP.color[0] = dP.color[1] = dP.color[2] = 1;
        double out[6] = {0, 0, 0, 0, 0, 0};
        projection::ParamGradRef<double> ref;
        ref.mean = out;
        ref.log_scale = out + 3;
        projection::projectBackward(g, i, ct, s, P, dP, ref);
        double scale = 0;
        for (double v : out) scale = std::max(scale, std::abs(v));
        if (i % 7 == 0) {
          // A scale clamped at e^60 has no gradient; the rest of such a Gaussian's chain is
          // rounding noise around zero (it covers everything), in either form.
          EXPECT_EQ(J[r][3], 0.0);
          EXPECT_EQ(out[3], 0.0);
          continue;
        }
        for (int k = 0; k < 6; ++k)
          EXPECT_NEAR(J[r][k], out[k], 1e-10 * scale + 1e-300) << i << " row " << r << " col " << k;
      }
    }
    EXPECT_GT(checked, 20);
  }
}

TEST(Fisher, FloatPassIsBitIdenticalAcrossRunsAndThreadCounts) {
  const Gaussians g = test::randomScene<double>(500, 2, 70, 1.5).cast<float>();
  const Camera cam = test::smallCamera(96, 80);
  RasterSettings s;
  s.sh_degree = 2;
  s.background = {0.2f, 0.3f, 0.1f};
  auto arrays = [](const Gaussians& H) { return std::make_tuple(H.means, H.log_scales, H.opacities, H.sh); };
  for (const auto& [name, kernels] : test::runnableFisherKernels()) {
    SCOPED_TRACE(name);
    const auto a = arrays(floatInformation(g, cam, s, kernels, 2));
    EXPECT_TRUE(a == arrays(floatInformation(g, cam, s, kernels, 2)));
    EXPECT_TRUE(a == arrays(floatInformation(g, cam, s, kernels, 1)));
    EXPECT_TRUE(a == arrays(floatInformation(g, cam, s, kernels, 0)));
  }
}

TEST(Fisher, DuplicateOfATrainViewScoresBelowAViewOfUnseenGaussians) {
  // Two clusters: the train camera sees only the left one; one candidate duplicates it,
  // the other looks at the right cluster.
  Gaussians g = test::randomScene<float>(24, 0, 5, 0.25);
  for (std::size_t i = 0; i < g.size(); ++i) g.means[3 * i] += (i % 2 ? 3.0f : -3.0f);
  RasterSettings s;
  const Intrinsics K = test::pinhole(32, 24, 30);
  const Camera left =
      Camera::lookAt(K, Eigen::Vector3d(-3, -3, 0), Eigen::Vector3d(-3, 0, 0), Eigen::Vector3d::UnitZ());
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
