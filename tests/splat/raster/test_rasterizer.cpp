#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <functional>
#include <random>
#include <utility>

#include "raster_test_scenes.h"
#include "splat/raster/rasterize_detail.h"
#include "tests/splat/gaussians_bits.h"

using namespace saresgs;

namespace {

// A linear loss L = sum_p w_p . rgb_p with fixed random weights: dL/drgb = w.
std::vector<double> lossWeights(int w, int h, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> nd(0, 1);
  std::vector<double> out(static_cast<std::size_t>(w) * h * 3);
  for (auto& v : out) v = nd(rng);
  return out;
}

double linearLoss(const RenderOutputT<double>& r, const std::vector<double>& w) {
  double s = 0;
  for (std::size_t k = 0; k < w.size(); ++k) s += w[k] * r.rgb[k];
  return s;
}

}  // namespace

class RasterGradient : public ::testing::TestWithParam<int> {};

TEST_P(RasterGradient, EveryParameterMatchesFiniteDifferences) {
  const int sh_degree = GetParam();
  const Camera cam = test::smallCamera();
  GaussiansD g = test::randomScene<double>(7, sh_degree, 10 + sh_degree);
  RasterSettings s;
  s.sh_degree = sh_degree;
  s.background = {0.2f, 0.5f, 0.7f};
  const auto w = lossWeights(cam.K.width, cam.K.height, 3);
  const auto fwd = rasterizeT(g, cam, s);
  GaussiansD grad = g.zerosLike();
  rasterizeBackwardT(g, cam, s, fwd, w.data(), grad);
  auto loss = [&] { return linearLoss(rasterizeT(g, cam, s), w); };
  test::GradCheck gc;
  test::checkGradients(g, grad, loss, gc);
  EXPECT_EQ(gc.bad, 0);
  EXPECT_LE(gc.kinks, gc.checked / 20) << "too many parameters on kinks: " << gc.kinks;
  int visible = 0;
  for (auto v : fwd.visible) visible += v;
  EXPECT_GE(visible, 5);  // the scene exercises the renderer
}

INSTANTIATE_TEST_SUITE_P(ShDegrees, RasterGradient, ::testing::Values(0, 1, 2, 3));

TEST(RasterGradient, MeanTwoDGradientMatchesAShiftOfThePrincipalPoint) {
  // Moving cx by h moves every 2D mean by h in x and changes nothing else that the
  // compositing sees, so dL/dcx = sum_i dL/dmean2d_x(i); likewise cy and y.
  Camera cam = test::smallCamera();
  GaussiansD g = test::randomScene<double>(5, 0, 21);
  RasterSettings s;
  s.guard_band = 100.0f;  // the guard band depends on cx; keep it out of reach
  const auto w = lossWeights(cam.K.width, cam.K.height, 4);
  const auto fwd = rasterizeT(g, cam, s);
  GaussiansD grad = g.zerosLike();
  std::vector<double> g2d(2 * g.size(), 0.0);
  rasterizeBackwardT(g, cam, s, fwd, w.data(), grad, &g2d);
  double sx = 0, sy = 0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    sx += g2d[2 * i];
    sy += g2d[2 * i + 1];
  }
  auto shifted = [&](double dx, double dy) {
    Camera c = cam;
    c.K.cx += dx;
    c.K.cy += dy;
    return linearLoss(rasterizeT(g, c, s), w);
  };
  const double h = 1e-6;
  EXPECT_NEAR(sx, (shifted(h, 0) - shifted(-h, 0)) / (2 * h), 1e-5 * std::max(1.0, std::abs(sx)));
  EXPECT_NEAR(sy, (shifted(0, h) - shifted(0, -h)) / (2 * h), 1e-5 * std::max(1.0, std::abs(sy)));
  EXPECT_GT(std::abs(sx) + std::abs(sy), 1e-3);
}

struct FloatCase {
  int gaussians, sh_degree;
  double spread;
  float background;
  std::uint64_t seed;
  int threads = 0;  // the rasterizer's (0: all cores)
};

class FloatPath : public ::testing::TestWithParam<FloatCase> {};

namespace {
void checkFloatAgainstDouble(const FloatCase& fc, RasterKernels kernels);
}  // namespace

// The float product path (SIMD kernels, every instruction set this CPU runs) against
// the same code in double.
TEST_P(FloatPath, MatchesDoublePath) {
  for (const auto& [name, kernels] : test::runnableKernels()) {
    SCOPED_TRACE(name);
    checkFloatAgainstDouble(GetParam(), kernels);
  }
}

// The baseline and avx2 kernel sets differ only in rounding (FMA, the order lanes are
// summed); avx512 is avx2 bit for bit (Fisher.Avx512WalkEqualsAvx2BitForBit,
// FloatPath.Avx512BackwardEqualsAvx2BitForBit).
TEST(FloatPath, KernelSetsAgree) {
  const Camera cam = test::smallCamera(72, 56);
  const Gaussians g = test::randomScene<double>(300, 2, 9, 1.2).cast<float>();
  RasterSettings s;
  s.sh_degree = 2;
  s.background = {0.1f, 0.2f, 0.3f};
  const auto w = lossWeights(72, 56, 10);
  const std::vector<float> wf(w.begin(), w.end());
  auto run = [&](RasterKernels kernels) {
    s.execution.kernels = kernels;
    const auto r = rasterizeT(g, cam, s);
    Gaussians grad = g.zerosLike();
    rasterizeBackwardT(g, cam, s, r, wf.data(), grad);
    return std::make_pair(r, grad);
  };
  if (!rasterCpuHasAvx2()) GTEST_SKIP() << "no AVX2 on this CPU";
  const auto [ra, ga] = run(RasterKernels::kAvx2);
  const auto [rb, gb] = run(RasterKernels::kBaseline);
  auto close = [](const std::vector<float>& a, const std::vector<float>& b) {
    double scale = 0, diff = 0;
    for (std::size_t k = 0; k < a.size(); ++k) {
      scale = std::max(scale, static_cast<double>(std::abs(a[k])));
      diff = std::max(diff, static_cast<double>(std::abs(a[k] - b[k])));
    }
    return diff <= 2e-3 * scale + 1e-6;
  };
  // A pixel may differ by one borderline contribution (the 1/255 and 1e-4 thresholds).
  int differ = 0;
  for (std::size_t k = 0; k < ra.contributors.size(); ++k) differ += ra.contributors[k] != rb.contributors[k];
  EXPECT_LE(differ, static_cast<int>(ra.contributors.size() / 500));
  int off = 0;
  for (std::size_t k = 0; k < ra.rgb.size(); ++k) off += std::abs(ra.rgb[k] - rb.rgb[k]) > 1e-5f;
  EXPECT_LE(off, static_cast<int>(ra.rgb.size() / 500));
  EXPECT_TRUE(close(ga.means, gb.means));
  EXPECT_TRUE(close(ga.log_scales, gb.log_scales));
  EXPECT_TRUE(close(ga.rotations, gb.rotations));
  EXPECT_TRUE(close(ga.opacities, gb.opacities));
  EXPECT_TRUE(close(ga.sh, gb.sh));
}

// The avx512 set's backward kernel (the AVX2 kernel on 32 registers) gives the avx2
// set's gradients bit for bit: with and without a background, small and wide Gaussians
// (the chord spans and the lattice), one thread and all.
TEST(FloatPath, Avx512BackwardEqualsAvx2BitForBit) {
  if (!rasterCpuHasAvx512()) GTEST_SKIP() << "no AVX-512F and AVX-512VL on this CPU (the avx512 set cannot run here)";
  const Camera cam = test::smallCamera(160, 120);
  const auto w = lossWeights(160, 120, 10);
  const std::vector<float> wf(w.begin(), w.end());
  int nonzero = 0;
  for (const double grow : {0.0, 1.5, 3.0}) {
    Gaussians g = test::randomScene<double>(400, 2, 31, 1.3).cast<float>();
    for (float& l : g.log_scales) l += static_cast<float>(grow);  // up to ~20x wider: chords
    for (const bool bg : {false, true}) {
      for (const int threads : {1, 0}) {
        SCOPED_TRACE("grow " + std::to_string(grow) + (bg ? " background" : "") + " threads " +
                     std::to_string(threads));
        RasterSettings s;
        s.sh_degree = 2;
        if (bg) s.background = {0.1f, 0.2f, 0.3f};
        s.execution.threads = threads;
        // Every gradient array and the 2D means' gradients, end to end.
        auto run = [&](RasterKernels kernels) {
          s.execution.kernels = kernels;
          const auto r = rasterizeT(g, cam, s);
          Gaussians grad = g.zerosLike();
          std::vector<float> mean2d(2 * g.size(), 0.0f);
          rasterizeBackwardT(g, cam, s, r, wf.data(), grad, &mean2d);
          return test::flattened(std::move(mean2d), grad);
        };
        const std::vector<float> a = run(RasterKernels::kAvx2), b = run(RasterKernels::kAvx512);
        ASSERT_TRUE(test::valuesBitEqual(b, a, "avx512", "avx2"));
        nonzero += static_cast<int>(std::count_if(a.begin(), a.end(), [](float v) { return v != 0.0f; }));
      }
    }
  }
  EXPECT_GT(nonzero, 10000);  // the comparison saw real gradients
}

namespace {
void checkFloatAgainstDouble(const FloatCase& fc, RasterKernels kernels) {
  const Camera cam = test::smallCamera(64, 48);
  const GaussiansD gd = test::randomScene<double>(fc.gaussians, fc.sh_degree, fc.seed, fc.spread);
  const Gaussians gf = gd.cast<float>();
  RasterSettings s;
  s.sh_degree = fc.sh_degree;
  s.execution.kernels = kernels;
  s.execution.threads = fc.threads;
  s.background = {fc.background, 0.5f * fc.background, 1.0f - fc.background};
  const auto rd = rasterizeT(gd, cam, s);
  const auto rf = rasterizeT(gf, cam, s);
  double max_diff = 0;
  for (std::size_t k = 0; k < rd.rgb.size(); ++k) max_diff = std::max(max_diff, std::abs(rd.rgb[k] - rf.rgb[k]));
  EXPECT_LT(max_diff, 1e-4);
  // Gradients to float precision, relative to the largest entry of each array.
  const auto w = lossWeights(64, 48, 6);
  std::vector<float> wf(w.begin(), w.end());
  GaussiansD gradd = gd.zerosLike();
  Gaussians gradf = gf.zerosLike();
  rasterizeBackwardT(gd, cam, s, rd, w.data(), gradd);
  rasterizeBackwardT(gf, cam, s, rf, wf.data(), gradf);
  auto compare = [](const std::vector<double>& a, const std::vector<float>& b, const char* name) {
    double scale = 0, diff = 0;
    for (std::size_t k = 0; k < a.size(); ++k) {
      scale = std::max(scale, std::abs(a[k]));
      diff = std::max(diff, std::abs(a[k] - b[k]));
    }
    EXPECT_LE(diff, 2e-3 * scale + 1e-6) << name;
  };
  test::forEachArrayPair(gradd, gradf, compare);
}
}  // namespace

INSTANTIATE_TEST_SUITE_P(Scenes, FloatPath,
                         ::testing::Values(FloatCase{60, 3, 0.9, 0.0f, 5}, FloatCase{300, 0, 0.6, 0.7f, 6},
                                           FloatCase{150, 1, 1.5, 0.3f, 7},
                                           // Thousands: the backward's per-Gaussian chain
                                           // runs over ranges longer than its 256-entry lists.
                                           FloatCase{3000, 2, 1.2, 0.2f, 8, 1}));

// Gaussians wider than 32 pixels take the kernels' chord bounds (per block row, only the
// columns the alpha ellipse can reach); smaller ones the plain rectangle. Long thin
// Gaussians at every angle, against the double path: a chord that cut off a pixel the
// per-pixel test passes would show here.
TEST(FloatPath, LongThinGaussiansMatchDouble) {
  const Camera cam = test::smallCamera(96, 72);
  GaussiansD gd = test::randomScene<double>(40, 0, 11, 0.5);
  for (int i = 0; i < 40; ++i) {
    gd.log_scales[3 * i] = std::log(0.6 + 0.02 * i);
    gd.log_scales[3 * i + 1] = std::log(0.01);
    gd.log_scales[3 * i + 2] = std::log(0.01);
    gd.opacities[i] = 2.0;
  }
  const Gaussians gf = gd.cast<float>();
  const auto w = lossWeights(96, 72, 12);
  const std::vector<float> wf(w.begin(), w.end());
  for (const auto& [name, kernels] : test::runnableKernels()) {
    RasterSettings s;
    s.execution.kernels = kernels;
    const auto rd = rasterizeT(gd, cam, s);
    const auto rf = rasterizeT(gf, cam, s);
    int wide = 0;
    for (float r : rf.radii) wide += r > 16.0f;
    ASSERT_GE(wide, 20) << name << ": the scene must exercise the chord bounds";
    double max_diff = 0;
    for (std::size_t k = 0; k < rd.rgb.size(); ++k) max_diff = std::max(max_diff, std::abs(rd.rgb[k] - rf.rgb[k]));
    EXPECT_LT(max_diff, 1e-4) << name;
    int differ = 0;
    for (std::size_t k = 0; k < rd.contributors.size(); ++k) differ += rd.contributors[k] != rf.contributors[k];
    EXPECT_LE(differ, static_cast<int>(rd.contributors.size() / 500)) << name;
    GaussiansD gradd = gd.zerosLike();
    Gaussians gradf = gf.zerosLike();
    rasterizeBackwardT(gd, cam, s, rd, w.data(), gradd);
    rasterizeBackwardT(gf, cam, s, rf, wf.data(), gradf);
    double scale = 0, diff = 0;
    for (std::size_t k = 0; k < gradd.means.size(); ++k) {
      scale = std::max(scale, std::abs(gradd.means[k]));
      diff = std::max(diff, std::abs(gradd.means[k] - gradf.means[k]));
    }
    EXPECT_LE(diff, 2e-3 * scale + 1e-6) << name;
  }
}

TEST(Rasterizer, BitIdenticalAcrossRunsAndThreadCounts) {
  const Camera cam = test::smallCamera(96, 80);
  const Gaussians g = test::randomScene<double>(400, 1, 8, 1.5).cast<float>();
  RasterSettings s;
  s.sh_degree = 1;
  std::vector<float> w(96 * 80 * 3, 0.5f);
  auto run = [&](int threads) {
    s.execution.threads = threads;
    const auto r = rasterizeT(g, cam, s);
    Gaussians grad = g.zerosLike();
    rasterizeBackwardT(g, cam, s, r, w.data(), grad);
    Gaussians sq = g.zerosLike();
    rasterizeSquaredGradientsT(g, cam, s, r, sq);
    return std::make_tuple(r.rgb, grad.means, grad.sh, sq.means);
  };
  for (const auto& [name, kernels] : test::runnableKernels()) {
    SCOPED_TRACE(name);
    s.execution.kernels = kernels;
    const auto a = run(2), b = run(2), c = run(1), d = run(0);
    EXPECT_TRUE(a == b);
    EXPECT_TRUE(a == c);
    EXPECT_TRUE(a == d);
  }
}

TEST(Rasterizer, SubsetRenderEqualsZeroOpacity) {
  const Camera cam = test::smallCamera(40, 32);
  Gaussians g = test::randomScene<double>(30, 0, 9).cast<float>();
  RasterSettings s;
  std::vector<std::uint8_t> mask(g.size(), 1);
  for (std::size_t i = 0; i < g.size(); i += 3) mask[i] = 0;
  const auto sub = rasterizeT(g, cam, s, mask);
  Gaussians zeroed = g;
  for (std::size_t i = 0; i < g.size(); ++i)
    if (!mask[i]) zeroed.opacities[i] = -1e30f;
  const auto ref = rasterizeT(zeroed, cam, s);
  EXPECT_TRUE(sub.rgb == ref.rgb);
  EXPECT_TRUE(sub.contributors == ref.contributors);
  const auto full = rasterizeT(g, cam, s);
  EXPECT_FALSE(sub.rgb == full.rgb);  // the mask really removes something
}

TEST(Rasterizer, ResidualBranchAmplifiesGradientBehindAMaskedGaussian) {
  // Gaussian k (index 0) in front of Gaussian i (index 1) on the central ray. With k
  // masked, d rgb / d c_i grows by 1 / (1 - alpha_k) (the paper's amplified gradient).
  const Camera cam = test::smallCamera(24, 20);
  GaussiansD g;
  g.max_sh_degree = 0;
  g.resize(2);
  const Eigen::Vector3d ray = cam.viewDirection(), C = cam.center();
  for (int k = 0; k < 3; ++k) {
    g.means[k] = C[k] + 2.5 * ray[k];
    g.means[3 + k] = C[k] + 3.5 * ray[k];
    g.log_scales[k] = g.log_scales[3 + k] = std::log(0.3);
  }
  g.rotations = {1, 0, 0, 0, 1, 0, 0, 0};
  g.opacities = {0.8, 0.5};
  g.sh = {0.4, 0.1, -0.2, 0.3, 0.2, 0.1};
  RasterSettings s;
  // One-hot loss at the pixel under the principal point, all channels.
  const auto uv = cam.project(C + 2.5 * ray);
  const int px = static_cast<int>(uv->x()), py = static_cast<int>(uv->y());
  std::vector<double> w(24 * 20 * 3, 0.0);
  for (int c = 0; c < 3; ++c) w[(py * 24 + px) * 3 + c] = 1.0;
  const auto full = rasterizeT(g, cam, s);
  GaussiansD gf = g.zerosLike();
  rasterizeBackwardT(g, cam, s, full, w.data(), gf);
  const std::vector<std::uint8_t> mask = {0, 1};
  const auto sub = rasterizeT(g, cam, s, mask);
  GaussiansD gs = g.zerosLike();
  rasterizeBackwardT(g, cam, s, sub, w.data(), gs);
  // alpha_k at that pixel, from the renderer's own alpha output with only k.
  const auto only_k = rasterizeT(g, cam, s, std::vector<std::uint8_t>{1, 0});
  const double alpha_k = only_k.alpha[py * 24 + px];
  ASSERT_GT(alpha_k, 0.3);
  for (int c = 0; c < 3; ++c) {
    ASSERT_GT(std::abs(gf.sh[3 + c]), 1e-6);
    EXPECT_NEAR(gs.sh[3 + c], gf.sh[3 + c] / (1 - alpha_k), 1e-9);
  }
}

TEST(Rasterizer, SquaredGradientsEqualSumOfPerPixelSquares) {
  const int W = 14, H = 12;
  const Camera cam = test::smallCamera(W, H);
  const GaussiansD g = test::randomScene<double>(6, 2, 12);
  RasterSettings s;
  s.sh_degree = 2;
  s.background = {0.3f, 0.3f, 0.3f};
  const auto fwd = rasterizeT(g, cam, s);
  GaussiansD sq = g.zerosLike();
  rasterizeSquaredGradientsT(g, cam, s, fwd, sq);
  // Brute force: one backward pass per pixel with dL/drgb = 1 on its three channels.
  GaussiansD brute = g.zerosLike();
  for (int p = 0; p < W * H; ++p) {
    std::vector<double> w(W * H * 3, 0.0);
    for (int c = 0; c < 3; ++c) w[p * 3 + c] = 1.0;
    GaussiansD gp = g.zerosLike();
    rasterizeBackwardT(g, cam, s, fwd, w.data(), gp);
    auto add = [](std::vector<double>& acc, const std::vector<double>& v) {
      for (std::size_t k = 0; k < v.size(); ++k) acc[k] += v[k] * v[k];
    };
    add(brute.means, gp.means);
    add(brute.log_scales, gp.log_scales);
    add(brute.opacities, gp.opacities);
    add(brute.sh, gp.sh);
  }
  auto expectClose = [](const std::vector<double>& a, const std::vector<double>& b, const char* name) {
    double total = 0;
    for (std::size_t k = 0; k < a.size(); ++k) {
      EXPECT_NEAR(a[k], b[k], 1e-9 * std::max(1.0, std::abs(b[k]))) << name << "[" << k << "]";
      total += b[k];
    }
    EXPECT_GT(total, 0.0) << name;
  };
  expectClose(sq.means, brute.means, "means");
  expectClose(sq.log_scales, brute.log_scales, "log_scales");
  expectClose(sq.opacities, brute.opacities, "opacities");
  expectClose(sq.sh, brute.sh, "sh");
  for (double v : sq.rotations) EXPECT_EQ(v, 0.0);  // rotations excluded
}
