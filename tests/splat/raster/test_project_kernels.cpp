// The SIMD projection kernels (splat/raster/project_kernels_impl.h) against
// projection::project<float>, bit for bit: every kernel set this CPU runs, SH degrees 0-3,
// ranges that end inside a vector, and Gaussians that each cull rule rejects (behind the
// camera, at the near plane, outside the guard band, transparent, degenerate, off screen,
// non-finite parameters), under ordinary, extreme and far-from-origin cameras.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numeric>
#include <random>
#include <string>

#include "raster_test_scenes.h"
#include "splat/raster/projection.h"
#include "splat/raster/raster_kernels.h"
#include "splat/raster/rasterize_detail.h"
#include "tests/splat/gaussians_bits.h"

using namespace saresgs;

namespace {

// n Gaussians about `centre` (within `spread`), seen by a camera looking at it, with
// every parameter drawn over a wide range and one Gaussian in seven made extreme.
Gaussians wideScene(int n, int sh_degree, std::uint64_t seed, const Eigen::Vector3d& centre, double spread) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> nd(0, 1);
  std::uniform_real_distribution<double> u(0, 1);
  Gaussians g;
  g.max_sh_degree = sh_degree;
  g.resize(n);
  const int K = g.shCoeffs();
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) g.means[3 * i + k] = static_cast<float>(centre(k) + spread * 2.0 * nd(rng));
    for (int k = 0; k < 3; ++k) g.log_scales[3 * i + k] = static_cast<float>(std::log(spread) - 3.0 + 2.0 * nd(rng));
    for (int k = 0; k < 4; ++k) g.rotations[4 * i + k] = static_cast<float>(nd(rng));
    g.opacities[i] = static_cast<float>(3.0 * nd(rng));
    for (int k = 0; k < K * 3; ++k) g.sh[i * K * 3 + k] = static_cast<float>((k < 3 ? 1.0 : 0.4) * nd(rng));
    switch (i % 7 == 6 ? static_cast<int>(u(rng) * 10) : -1) {
      case 0:
        for (int k = 0; k < 4; ++k) g.rotations[4 * i + k] = 0.0f;
        break;  // identity
      case 1:
        g.rotations[4 * i] = 1e-20f;
        break;
      case 2:
        g.log_scales[3 * i] = 200.0f;
        break;  // clamped at e^60
      case 3:
        g.log_scales[3 * i + 1] = -200.0f;
        break;
      case 4:
        g.opacities[i] = (u(rng) < 0.5 ? -1.0f : 1.0f) * 1e30f;
        break;
      case 5:
        g.means[3 * i + 2] = nan;
        break;
      case 6:
        g.log_scales[3 * i + 2] = inf;
        break;
      case 7:
        g.opacities[i] = nan;
        break;
      case 8:
        g.sh[i * K * 3] = -1e30f;
        break;  // a clamped channel
      case 9:
        for (int k = 0; k < 3; ++k) g.log_scales[3 * i + k] = -30.0f;
        break;  // eps2d only
      default:
        break;
    }
  }
  return g;
}

std::uint32_t bits(float v) { return std::bit_cast<std::uint32_t>(v); }

// Every field project() defines for a visible Gaussian, bit for bit; the flag for all.
void expectSame(const projection::Projected<float>& a, const projection::Projected<float>& b, std::size_t i,
                int& visible) {
  ASSERT_EQ(a.visible, b.visible) << "Gaussian " << i;
  if (!a.visible) return;
  ++visible;
  auto same = [&](float x, float y, const char* what) {
    EXPECT_EQ(bits(x), bits(y)) << "Gaussian " << i << " " << what << ": " << x << " vs " << y;
  };
  same(a.mean2d[0], b.mean2d[0], "mean x");
  same(a.mean2d[1], b.mean2d[1], "mean y");
  for (int k = 0; k < 3; ++k) {
    same(a.conic[k], b.conic[k], "conic");
    same(a.cov2d[k], b.cov2d[k], "cov2d");
    same(a.color[k], b.color[k], "colour");
    EXPECT_EQ(a.clamped[k], b.clamped[k]) << "Gaussian " << i;
  }
  same(a.depth, b.depth, "depth");
  same(a.opacity, b.opacity, "opacity");
  same(a.half[0], b.half[0], "half x");
  same(a.half[1], b.half[1], "half y");
  same(a.radius, b.radius, "radius");
}

struct ProjectCase {
  const char* name;
  Camera cam;
  Eigen::Vector3d centre;
  double spread;
};

std::vector<ProjectCase> projectCases() {
  std::vector<ProjectCase> cases;
  cases.push_back({"ordinary", test::smallCamera(160, 120), Eigen::Vector3d::Zero(), 0.6});
  Intrinsics wide;  // about 175 degrees across
  wide.width = 320;
  wide.height = 240;
  wide.fx = wide.fy = 6.0;
  wide.cx = 160.3;
  wide.cy = 119.6;
  cases.push_back(
      {"extreme field of view", Camera::lookAt(wide, {0.2, -3.0, 0.4}, {0, 0, 0}), Eigen::Vector3d::Zero(), 1.5});
  Intrinsics tele = wide;  // about 0.03 degrees
  tele.fx = tele.fy = 6e5;
  cases.push_back({"telephoto", Camera::lookAt(tele, {0.2, -3.0, 0.4}, {0, 0, 0}), Eigen::Vector3d::Zero(), 1e-3});
  Intrinsics k = wide;
  k.fx = k.fy = 300.0;
  const Eigen::Vector3d far(3e4, -2e4, 1e4);
  cases.push_back({"far from the origin", Camera::lookAt(k, far + Eigen::Vector3d(0.2, -3.0, 0.4), far), far, 0.6});
  cases.push_back({"tiny scene", Camera::lookAt(k, {2e-4, -3e-3, 4e-4}, {0, 0, 0}), Eigen::Vector3d::Zero(), 6e-4});
  cases.push_back({"huge scene", Camera::lookAt(k, {2e4, -3e5, 4e4}, {0, 0, 0}), Eigen::Vector3d::Zero(), 6e4});
  return cases;
}

// One (camera case, SH degree) of the per-Gaussian stage tests: n Gaussians of wideScene,
// settings at that degree, and every Gaussian's scalar projection (the stage's input).
struct StageCase {
  StageCase(const ProjectCase& pc, int n, int degree, std::uint64_t seed)
      : g(wideScene(n, degree, seed, pc.centre, pc.spread)), camT(pc.cam, s.guard_band), proj(g.size()) {
    s.sh_degree = degree;
    for (std::size_t i = 0; i < g.size(); ++i) proj[i] = projection::project(g, i, camT, s);
  }
  Gaussians g;
  RasterSettings s;
  projection::CameraT<float> camT;
  std::vector<projection::Projected<float>> proj;
};

// Runs `stage` onto a copy of `start` with every kernel set this CPU runs, and asserts
// that it gives `ref` bit for bit.
void expectEveryKernelGives(const ProjectCase& pc, int degree, RasterSettings s, const Gaussians& start,
                            const Gaussians& ref, const std::function<void(const RasterSettings&, Gaussians&)>& stage) {
  for (const auto& [name, kernels] : test::runnableKernels()) {
    SCOPED_TRACE(std::string(pc.name) + ", " + name + ", degree " + std::to_string(degree));
    s.execution.kernels = kernels;
    Gaussians got = start;
    stage(s, got);
    ASSERT_TRUE(test::arraysBitEqual(got, ref));
  }
}

}  // namespace

// Every kernel set, every SH degree, several cameras: the SIMD projection is project<float>.
TEST(ProjectKernels, EqualProjectBitForBit) {
  int visible = 0, culled = 0, clamped = 0;
  for (const ProjectCase& pc : projectCases()) {
    for (int degree = 0; degree <= 3; ++degree) {
      const Gaussians g = wideScene(1003, degree, 11 + degree, pc.centre, pc.spread);
      RasterSettings s;
      s.sh_degree = degree;
      const projection::CameraT<float> camT(pc.cam, s.guard_band);
      for (const auto& [name, kernels] : test::runnableKernels()) {
        SCOPED_TRACE(std::string(pc.name) + ", " + name + ", degree " + std::to_string(degree));
        s.execution.kernels = kernels;
        std::vector<projection::Projected<float>> out;
        projectRangeFloat(g, pc.cam, s, 0, g.size(), out);
        for (std::size_t i = 0; i < g.size(); ++i) {
          const projection::Projected<float> ref = projection::project(g, i, camT, s);
          expectSame(out[i], ref, i, visible);
          if (::testing::Test::HasFatalFailure()) return;
          culled += !ref.visible;
          clamped += ref.visible && (ref.clamped[0] || ref.clamped[1] || ref.clamped[2]);
        }
      }
    }
  }
  // The cases reach both outcomes, and the clamped colour, many times.
  EXPECT_GT(visible, 3000);
  EXPECT_GT(culled, 3000);
  EXPECT_GT(clamped, 300);
}

// A range that starts and ends inside a vector: only its Gaussians are written, each as
// project() gives it.
TEST(ProjectKernels, PartialRangesWriteOnlyTheirGaussians) {
  const Camera cam = test::smallCamera(160, 120);
  const Gaussians g = wideScene(40, 2, 5, Eigen::Vector3d::Zero(), 0.6);
  RasterSettings s;
  s.sh_degree = 2;
  const projection::CameraT<float> camT(cam, s.guard_band);
  for (const auto& [name, kernels] : test::runnableKernels()) {
    s.execution.kernels = kernels;
    for (const auto& [b, e] : std::vector<std::pair<std::size_t, std::size_t>>{{3, 4}, {5, 18}, {1, 40}, {7, 7}}) {
      SCOPED_TRACE(std::string(name) + " [" + std::to_string(b) + ", " + std::to_string(e) + ")");
      std::vector<projection::Projected<float>> out(g.size());
      for (auto& P : out) P.radius = -123.0f;  // a marker no projection writes
      projectRangeFloat(g, cam, s, b, e, out);
      int visible = 0;
      for (std::size_t i = 0; i < g.size(); ++i) {
        if (i < b || i >= e) {
          EXPECT_EQ(out[i].radius, -123.0f) << "Gaussian " << i << " outside the range was written";
          continue;
        }
        expectSame(out[i], projection::project(g, i, camT, s), i, visible);
      }
    }
  }
  std::vector<projection::Projected<float>> out;
  EXPECT_THROW(projectRangeFloat(g, cam, s, 5, 41, out), std::invalid_argument);
}

// The SIMD projectBackward (every kernel set, SH degrees 0-3, the same cameras and extreme
// Gaussians): what it adds to a gradient that already holds values is what the scalar
// projectBackward adds, bit for bit, Gaussian by Gaussian, and nothing reaches a Gaussian
// not listed.
TEST(ProjectKernels, BackwardEqualsProjectBackwardBitForBit) {
  int chained = 0, nonzero = 0;
  for (const ProjectCase& pc : projectCases()) {
    for (int degree = 0; degree <= 3; ++degree) {
      const StageCase c(pc, 603, degree, 21 + degree);
      const Gaussians& g = c.g;
      std::mt19937_64 rng(degree + 5);
      std::normal_distribution<float> nd(0, 1);
      std::vector<std::uint32_t> idx;
      std::vector<projection::ProjectedGrad<float>> dP;
      for (std::size_t i = 0; i < g.size(); ++i) {
        // Visible Gaussians (as the backward sees them), two in three, in a shuffled order.
        if (!c.proj[i].visible || i % 3 == 2) continue;
        idx.push_back(static_cast<std::uint32_t>(i));
        projection::ProjectedGrad<float> d;
        d.opacity = nd(rng);
        for (float& v : d.mean2d) v = nd(rng);
        for (float& v : d.conic) v = 10.0f * nd(rng);
        for (float& v : d.color) v = i % 11 == 0 ? 0.0f : nd(rng);
        dP.push_back(d);
      }
      std::shuffle(idx.begin(), idx.end(), rng);  // dP[j] stays with position j
      Gaussians start = g.zerosLike();
      start.forEachArray([&](std::vector<float>& a, std::size_t) {
        for (float& v : a) v = 0.01f * nd(rng);
      });
      Gaussians ref = start;
      for (std::size_t j = 0; j < idx.size(); ++j)
        projection::projectBackward(g, idx[j], c.camT, c.s, c.proj[idx[j]], dP[j],
                                    projection::ParamGradRef<float>::of(ref, idx[j]));
      expectEveryKernelGives(pc, degree, c.s, start, ref, [&](const RasterSettings& s, Gaussians& got) {
        projectBackwardFloat(g, pc.cam, s, idx, c.proj, dP, got);
      });
      if (::testing::Test::HasFatalFailure()) return;
      chained += static_cast<int>(idx.size() * test::runnableKernels().size());
      nonzero += test::countChanged(start, ref);
    }
  }
  EXPECT_GT(chained, 3000);    // the comparison saw many Gaussians
  EXPECT_GT(nonzero, 100000);  // and real gradients
  // Mismatched lists and indices beyond the model are refused, not read.
  const Camera cam = test::smallCamera(64, 48);
  const Gaussians g = wideScene(20, 1, 3, Eigen::Vector3d::Zero(), 0.6);
  Gaussians grad = g.zerosLike();
  const std::vector<projection::Projected<float>> proj(g.size());
  RasterSettings s;
  EXPECT_THROW(projectBackwardFloat(g, cam, s, {1, 2}, proj, {{}}, grad), std::invalid_argument);
  EXPECT_THROW(projectBackwardFloat(g, cam, s, {20}, proj, {{}}, grad), std::invalid_argument);
  EXPECT_THROW(fisherChainFloat(g, cam, s, {1}, proj, std::vector<double>(5), grad), std::invalid_argument);
  EXPECT_THROW(fisherChainFloat(g, cam, s, {25}, proj, std::vector<double>(raster_kernels::kFisherSlot), grad),
               std::invalid_argument);
}

// The Fisher pass's per-Gaussian stage by the SIMD kernels equals the scalar reference bit
// for bit (every kernel set, SH degrees 0-3, the same cameras and extreme Gaussians, tile
// moments drawn over several orders of magnitude, onto squared gradients already holding
// values).
TEST(ProjectKernels, FisherChainEqualsReferenceBitForBit) {
  constexpr int kSlot = raster_kernels::kFisherSlot;
  int chained = 0, changed = 0;
  for (const ProjectCase& pc : projectCases()) {
    for (int degree = 0; degree <= 3; ++degree) {
      const StageCase c(pc, 403, degree, 31 + degree);
      const Gaussians& g = c.g;
      std::mt19937_64 rng(degree + 9);
      std::normal_distribution<double> nd(0, 1);
      std::vector<std::uint32_t> idx;
      std::vector<double> moments;
      for (std::size_t i = 0; i < g.size(); ++i) {
        if (!c.proj[i].visible || i % 4 == 3) continue;
        idx.push_back(static_cast<std::uint32_t>(i));
        // Even moments (E_ij with i + j even and W) non-negative, as sums of squares are.
        for (int m = 0; m < kSlot; ++m) {
          const double v = std::pow(10.0, 3.0 * nd(rng)) * nd(rng);
          const bool even = m == raster_kernels::kE00 || m == raster_kernels::kE20 || m == raster_kernels::kE02 ||
                            m == raster_kernels::kE40 || m == raster_kernels::kE22 || m == raster_kernels::kE04 ||
                            m == raster_kernels::kW;
          moments.push_back(even ? std::abs(v) : v);
        }
      }
      std::vector<std::uint32_t> order(idx.size());
      std::iota(order.begin(), order.end(), 0u);
      std::shuffle(order.begin(), order.end(), rng);
      std::vector<std::uint32_t> sidx;
      std::vector<double> smo;
      for (const std::uint32_t j : order) {
        sidx.push_back(idx[j]);
        smo.insert(smo.end(), moments.begin() + j * kSlot, moments.begin() + (j + 1) * kSlot);
      }
      Gaussians start = g.zerosLike();
      start.forEachArray([&](std::vector<float>& a, std::size_t) {
        for (float& v : a) v = static_cast<float>(std::abs(0.01 * nd(rng)));
      });
      Gaussians ref = start;
      for (std::size_t j = 0; j < sidx.size(); ++j)
        fisherChainReference(g, pc.cam, c.s, sidx[j], c.proj[sidx[j]], &smo[j * kSlot], ref);
      expectEveryKernelGives(pc, degree, c.s, start, ref, [&](const RasterSettings& s, Gaussians& got) {
        fisherChainFloat(g, pc.cam, s, sidx, c.proj, smo, got);
      });
      if (::testing::Test::HasFatalFailure()) return;
      chained += static_cast<int>(sidx.size() * test::runnableKernels().size());
      changed += test::countChanged(start, ref);
    }
  }
  EXPECT_GT(chained, 2000);
  EXPECT_GT(changed, 50000);
}
