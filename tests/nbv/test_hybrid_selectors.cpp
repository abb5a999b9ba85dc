// The selectors that combine evidence (log-det Fisher, the hybrid of Fisher and
// occlusion-aware surface coverage) on constructed cases where the right answer is known.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/pinhole.h"
#include "geometry/error.h"
#include "geometry/occupancy/candidate_sets.h"
#include "geometry/occupancy/occupancy_grid.h"
#include "nbv/selectors.h"
#include "nbv/surface_coverage.h"
#include "splat/fisher.h"

namespace saresgs {
namespace {

// Two Gaussians; only the first two mean entries carry information.
GaussiansT<double> information(double a, double b) {
  GaussiansT<double> h;
  h.resize(2);
  h.means[0] = a;
  h.means[1] = b;
  return h;
}

// The chosen views already inform both parameters equally (H = 1 each). A redundant view
// piles 100 more onto the first parameter, the one nearby chosen views already constrain;
// a complementary view adds 10 to each. The trace counts information linearly and
// prefers the redundant view (100 > 20); the log-det gain is what the pair of parameters'
// joint uncertainty loses, log(101) = 4.62 < 2 log(11) = 4.80, and prefers the
// complementary one.
TEST(HybridSelectors, LogDetRanksARedundantViewBelowAComplementaryOneWhereTheTraceDoesNot) {
  const double lambda = 1e-6;
  const GaussiansT<double> H = information(1, 1), redundant = information(100, 0), complementary = information(10, 10);
  EXPECT_GT(fisherScore(redundant, H, lambda), fisherScore(complementary, H, lambda));
  EXPECT_LT(fisherLogDetScore(redundant, H, lambda), fisherLogDetScore(complementary, H, lambda));
  EXPECT_NEAR(fisherLogDetScore(redundant, H, lambda), std::log(101.0), 1e-5);
  EXPECT_NEAR(fisherLogDetScore(complementary, H, lambda), 2 * std::log(11.0), 1e-5);
  // A view that adds nothing gains nothing under either criterion.
  EXPECT_EQ(fisherLogDetScore(information(0, 0), H, lambda), 0.0);
}

TEST(HybridSelectors, HybridScoresNormaliseEachKindOfEvidenceByItsMaximum) {
  const std::vector<double> f = {2, 4, 1}, n = {30, 0, 10};
  // w = 0: Fisher alone, w = 1: new surface alone, both scaled to a maximum of 1.
  EXPECT_EQ(hybridScores(f, n, 0), (std::vector<double>{0.5, 1, 0.25}));
  const std::vector<double> cover = hybridScores(f, n, 1);
  EXPECT_DOUBLE_EQ(cover[0], 1);
  EXPECT_DOUBLE_EQ(cover[1], 0);
  EXPECT_DOUBLE_EQ(cover[2], 1.0 / 3);
  const std::vector<double> half = hybridScores(f, n, 0.5);
  EXPECT_DOUBLE_EQ(half[0], 0.75);
  EXPECT_DOUBLE_EQ(half[1], 0.5);
  EXPECT_DOUBLE_EQ(half[2], 0.5 * 0.25 + 0.5 / 3);
  // Nothing new to see anywhere: the surface term drops out and Fisher decides.
  EXPECT_EQ(hybridScores(f, {0, 0, 0}, 0.5), (std::vector<double>{0.25, 0.5, 0.125}));
  // A NaN score counts as nothing and does not poison the others.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> h = hybridScores({nan, 2, 1}, n, 0.5);
  EXPECT_DOUBLE_EQ(h[0], 0.5);
  EXPECT_DOUBLE_EQ(h[1], 0.5);
  EXPECT_THROW(hybridScores(f, {1, 2}, 0.5), std::invalid_argument);
  EXPECT_THROW(hybridScores(f, n, 1.5), std::invalid_argument);
}

// A wall at x = 0 hides a panel at x = -1.5 from the chosen view A (at x = +3, looking
// along -x). Candidate B looks from behind (x = -4) and sees the panel; candidate C stands
// next to A and sees the wall again. Every voxel is inside every frustum, so frustum sets
// call the panel observed by A and give B nothing new; the Embree-visible sets know that A
// never saw the panel, and the hybrid picks B.
Scene occluderScene() {
  Scene s;
  s.source = "occluder scene";
  for (int i = 0; i <= 200; ++i)
    for (int j = 0; j <= 200; ++j) s.points.push_back({Eigen::Vector3d(0, -1 + 0.01 * i, -1 + 0.01 * j), {}});
  for (int i = 0; i <= 100; ++i)
    for (int j = 0; j <= 100; ++j) s.points.push_back({Eigen::Vector3d(-1.5, -0.5 + 0.01 * i, -0.5 + 0.01 * j), {}});
  const Intrinsics K = test::pinhole(64, 48, 60);
  const Eigen::Vector3d eyes[] = {{3, 0, 0}, {-4, 0, 0}, {3, 0.3, 0}};
  const Eigen::Vector3d targets[] = {{0, 0, 0}, {0, 0, 0}, {0, 0.3, 0}};
  for (int v = 0; v < 3; ++v) {
    SceneView view;
    view.name = std::string(1, static_cast<char>('A' + v));
    view.camera = Camera::lookAt(K, eyes[v], targets[v], Eigen::Vector3d::UnitZ());
    s.views.push_back(view);
    s.train.push_back(v);
  }
  s.finalize();
  return s;
}

// Surface coverage of the occluder scene: a 64^3 grid, every pixel cast.
SurfaceCoverageOptions occluderCoverageOptions() {
  SurfaceCoverageOptions o;
  o.grid.resolution = 64;
  o.stride = 1;
  return o;
}

TEST(HybridSelectors, HybridPrefersUnobservedSurfaceBehindAnOccluderThatFrustumSetsMiss) {
  const Scene s = occluderScene();
  const SurfaceCoverageOptions o = occluderCoverageOptions();
  SurfaceCoverage cov(s, o);
  ASSERT_GT(cov.surfaceCount(), 1000u);
  cov.observe({0});
  const std::vector<double> fresh = cov.newSurface({1, 2});
  EXPECT_GT(fresh[0], 300) << "B sees the hidden panel";
  EXPECT_LT(fresh[1], 0.05 * fresh[0]) << "C sees the wall A saw";
  // Without the tolerance, C's rays hit wall voxels between A's samples: sampling noise
  // that the tolerance absorbs.
  SurfaceCoverageOptions exact = o;
  exact.tolerance = 0;
  SurfaceCoverage strict(s, exact);
  strict.observe({0});
  EXPECT_GT(strict.newSurface({2})[0], fresh[1]);
  // Frustum sets: A's frustum already holds everything B's does.
  std::vector<Eigen::Vector3d> pts;
  for (const auto& p : s.points) pts.push_back(p.xyz);
  OccupancyOptions oo;
  oo.resolution = 64;
  const OccupancyGrids grids = OccupancyGrids::fromSfm(pts, oo);
  const VoxelSet fa = frustumSet(grids, s.views[0].camera), fb = frustumSet(grids, s.views[1].camera),
                 fc = frustumSet(grids, s.views[2].camera);
  EXPECT_EQ(differenceSize(fb, fa), 0u);
  EXPECT_EQ(differenceSize(fc, fa), 0u);
  // With equal Fisher evidence, the hybrid picks B at any positive weight.
  for (double w : {0.1, 0.5, 1.0}) {
    const std::vector<double> h = hybridScores({1.0, 1.0}, fresh, w);
    EXPECT_EQ(argmaxScore(h, {1, 2}), 0u) << w;
  }
  // Observing is a union: observing B then gives B nothing new.
  cov.observe({1, 0});
  EXPECT_EQ(cov.newSurface({1})[0], 0.0);
}

// Facility location over views, against its definition computed from the pairwise
// similarities: with A held, the view from behind (B) covers what nothing covers yet and
// gains more than C, a second look at what A covers.
TEST(HybridSelectors, FacilityGainIsTheRiseInCoverageOfTheTrainViews) {
  const Scene s = occluderScene();
  const SurfaceCoverageOptions o = occluderCoverageOptions();
  SurfaceCoverage cov(s, o);
  EXPECT_EQ(cov.similarity(1, 1), 1.0);
  EXPECT_EQ(cov.similarity(0, 2), cov.similarity(2, 0));
  EXPECT_GT(cov.similarity(0, 2), 0.5) << "A and C see the same wall";
  EXPECT_LT(cov.similarity(0, 1), cov.similarity(0, 2));
  cov.observe({0});
  const std::vector<int> all = {0, 1, 2};
  const std::vector<double> g = cov.facilityGain({1, 2}, all);
  auto J = [&](int a, int b) { return cov.similarity(a, b); };
  const double gain_b = 0 + (1 - J(1, 0)) + std::max(0.0, J(2, 1) - J(2, 0));
  const double gain_c = 0 + std::max(0.0, J(1, 2) - J(1, 0)) + (1 - J(2, 0));
  EXPECT_DOUBLE_EQ(g[0], gain_b);
  EXPECT_DOUBLE_EQ(g[1], gain_c);
  EXPECT_GT(g[0], g[1]);
  // Holding every view leaves nothing to gain.
  cov.observe({1, 2});
  for (double x : cov.facilityGain({0, 1, 2}, all)) EXPECT_EQ(x, 0.0);
}

TEST(HybridSelectors, SurfaceCoverageNeedsSparsePoints) {
  Scene s = occluderScene();
  s.points.clear();
  EXPECT_THROW(SurfaceCoverage(s, {}), InputError);
}

}  // namespace
}  // namespace saresgs
