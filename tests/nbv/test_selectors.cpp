// Selectors without grids (random, farthest view sampling, argmax and top-N % rules) and
// AUSE against hand-computable cases.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "nbv/active_run.h"
#include "nbv/ause.h"
#include "nbv/selectors.h"
#include "common/ring_scene.h"

namespace saresgs {
namespace {

// n 32x24 cameras on a ring of radius 4 in the plane z = 0, every one a train view.
Scene ringScene(int n) {
  return test::cameraRing(
      n, test::pinhole(32, 24, 30), 4, 0, [](int i) { return std::to_string(i); }, false);
}

TEST(Selectors, FarthestViewPicksTheOppositeCamera) {
  const Scene s = ringScene(12);
  // Chosen 0 and 1 on a ring of 12; the nearest-chosen distances in steps are
  // 3 -> 2, 5 -> 4, 7 -> 5 (to 0 the other way round), 9 -> 3.
  const std::vector<int> chosen = {0, 1}, cand = {3, 5, 7, 9};
  for (ViewDistance m : {ViewDistance::kEuclidean, ViewDistance::kGreatCircle}) {
    const auto scores = farthestViewScores(s, chosen, cand, m, Eigen::Vector3d::Zero());
    EXPECT_EQ(cand[argmaxScore(scores, cand)], 7) << static_cast<int>(m);
    if (m == ViewDistance::kGreatCircle)
      EXPECT_NEAR(scores[2], 5 * 2 * M_PI / 12, 1e-12);
    else
      EXPECT_NEAR(scores[1], 2 * 4 * std::sin(4 * M_PI / 12), 1e-12);  // chord of 4 steps
  }
}

TEST(Selectors, GreatCircleIgnoresRadius) {
  Scene s = ringScene(4);
  // Pull view 2 (opposite) close to the centre along its direction: Euclidean distance to
  // view 0 shrinks, the angle does not.
  s.views[2].camera = Camera::lookAt(s.views[2].camera.K, Eigen::Vector3d(-0.5, 0, 0), Eigen::Vector3d(1, 0, 0),
                                     Eigen::Vector3d::UnitZ());
  const std::vector<int> cand = {1, 2};
  EXPECT_EQ(
      cand[argmaxScore(farthestViewScores(s, {0}, cand, ViewDistance::kGreatCircle, Eigen::Vector3d::Zero()), cand)],
      2);
  EXPECT_EQ(
      cand[argmaxScore(farthestViewScores(s, {0}, cand, ViewDistance::kEuclidean, Eigen::Vector3d::Zero()), cand)], 1);
}

TEST(Selectors, ArgmaxAndRandom) {
  const std::vector<int> cand = {10, 4, 7, 2, 9};
  const std::vector<double> scores = {1, 3, 3, NAN, 0.5};
  EXPECT_EQ(cand[argmaxScore(scores, cand)], 4);  // tie 4/7 -> lower view index; NaN never wins
  std::mt19937_64 rng(1);
  std::set<int> seen;
  for (int i = 0; i < 200; ++i) seen.insert(selectRandom(cand, rng));
  EXPECT_EQ(seen, std::set<int>(cand.begin(), cand.end()));
  EXPECT_THROW(selectRandom({}, rng), std::invalid_argument);
}

TEST(Ause, PerfectReversedAndUndefined) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<double> err(1000), rev(1000), noise(1000);
  for (int i = 0; i < 1000; ++i) {
    err[i] = u(rng);
    rev[i] = -err[i];
    noise[i] = u(rng);
  }
  const auto perfect = sparsification(err, err);
  ASSERT_TRUE(perfect);
  EXPECT_NEAR(perfect->ause, 0.0, 1e-12);
  EXPECT_NEAR(perfect->oracle[0], 1.0, 1e-12);
  const auto reversed = sparsification(err, rev), random = sparsification(err, noise);
  ASSERT_TRUE(reversed && random);
  EXPECT_GT(reversed->ause, random->ause);
  EXPECT_GT(random->ause, perfect->ause + 0.1);
  // Uniform errors, random ranking: the curve stays ~1, the oracle at fraction f is
  // (1 - f) (the mean of the rest of a uniform sample): AUSE ~ 1 - mean(1 - f) ~ 0.5.
  EXPECT_NEAR(random->ause, 0.5, 0.06);
  EXPECT_FALSE(sparsification(std::vector<double>(50, 1.0), std::vector<double>(50, 1.0)));
  EXPECT_FALSE(sparsification(std::vector<double>(500, 0.0), std::vector<double>(500, 1.0)));
}

}  // namespace
}  // namespace saresgs

namespace saresgs {
namespace {

Scene lineScene(const std::vector<double>& xs) {
  Scene s = ringScene(static_cast<int>(xs.size()));
  for (std::size_t i = 0; i < xs.size(); ++i)  // all look along +y: only the centres differ
    s.views[i].camera = Camera::lookAt(s.views[i].camera.K, Eigen::Vector3d(xs[i], 0, 0), Eigen::Vector3d(xs[i], 5, 0),
                                       Eigen::Vector3d::UnitZ());
  return s;
}

// Held view 0 at x = 0; ten views crowd about x = 5 and one stands alone at x = -7. Farthest
// view sampling takes the loner (the larger gap); k-median counts the views each gap holds
// and takes the crowd's middle, the right answer for test views that follow the capture.
TEST(Selectors, KmedianFillsTheCrowdedGapWhereFarthestViewTakesTheLoner) {
  std::vector<double> xs = {0, -7};
  for (int i = 0; i < 10; ++i) xs.push_back(4.55 + 0.1 * i);
  const Scene s = lineScene(xs);
  std::vector<int> cand;
  for (int i = 1; i < static_cast<int>(xs.size()); ++i) cand.push_back(i);
  EXPECT_EQ(cand[argmaxScore(fvsScores(s, {0}, cand), cand)], 1);
  const std::vector<double> g = kmedianGains(s, {0}, cand, s.train, 1.0);
  const int pick = cand[argmaxScore(g, cand)];
  EXPECT_TRUE(pick == 6 || pick == 7) << pick;  // x = 4.95 or 5.05, the crowd's medians
  EXPECT_NEAR(g[0], 7, 1e-12);                  // the loner only helps itself
}

// The gain is what its docstring says: the drop of the summed distance to the nearest held
// view when the candidate joins, checked against the objective computed from scratch on a
// random capture with turned cameras (so the angle term counts).
TEST(Selectors, KmedianGainIsTheDropOfTheSummedNearestPoseDistance) {
  Scene s = ringScene(16);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-3, 3);
  for (SceneView& v : s.views)
    v.camera = Camera::lookAt(v.camera.K, Eigen::Vector3d(u(rng), u(rng), u(rng)), Eigen::Vector3d(u(rng), u(rng), 9),
                              Eigen::Vector3d::UnitZ());
  const double scale = poseAngleScale(s);
  auto objective = [&](const std::vector<int>& held) {
    double sum = 0;
    for (int t : s.train) {
      double m = std::numeric_limits<double>::infinity();
      for (int h : held) m = std::min(m, poseDistance(s.views[t].camera, s.views[h].camera, scale));
      sum += m;
    }
    return sum;
  };
  const std::vector<int> held = {2, 11}, cand = {0, 1, 5, 8, 13, 15};
  const std::vector<double> g = kmedianGains(s, held, cand, s.train, scale);
  for (std::size_t i = 0; i < cand.size(); ++i) {
    std::vector<int> more = held;
    more.push_back(cand[i]);
    EXPECT_NEAR(g[i], objective(held) - objective(more), 1e-9) << cand[i];
  }
  // Nothing held yet: still finite, and the most central view gains the most.
  for (double x : kmedianGains(s, {}, cand, s.train, scale)) EXPECT_TRUE(std::isfinite(x));
  EXPECT_THROW(kmedianGains(s, held, cand, s.train, -1), std::invalid_argument);
}

// fisher-kmedian's gain: the k-median gain with each view weighted by how unsure the model
// is of it. On a line of cameras 0..9 with 0 held, weight only on the far end (7, 8, 9):
// the far end's median, 8, gains 6 + 8 + 8 = 22, its neighbours 21, the unweighted median
// lies in the middle. The weighted gain is the weighted drop of the objective.
TEST(Selectors, WeightedKmedianServesTheViewsTheModelIsUnsureOf) {
  std::vector<double> xs;
  for (int i = 0; i < 10; ++i) xs.push_back(i);
  const Scene s = lineScene(xs);
  std::vector<int> cand;
  for (int i = 1; i < 10; ++i) cand.push_back(i);
  const std::vector<double> w = {0, 0, 0, 0, 0, 0, 1, 1, 1};  // per candidate (the population)
  const std::vector<double> g = kmedianGains(s, {0}, cand, cand, 1.0, w);
  EXPECT_EQ(cand[argmaxScore(g, cand)], 8);
  EXPECT_NEAR(g[7], 22, 1e-12);
  EXPECT_NEAR(g[6], 21, 1e-12);
  EXPECT_NEAR(g[8], 21, 1e-12);
  const std::vector<double> u = kmedianGains(s, {0}, cand, cand, 1.0);
  const int uniform_pick = cand[argmaxScore(u, cand)];
  EXPECT_TRUE(uniform_pick == 5 || uniform_pick == 6) << uniform_pick;
  // Equal weights rank as no weights.
  const std::vector<double> twos = kmedianGains(s, {0}, cand, cand, 1.0, std::vector<double>(cand.size(), 2.0));
  for (std::size_t i = 0; i < cand.size(); ++i) EXPECT_NEAR(twos[i], 2 * u[i], 1e-12);
  EXPECT_THROW(kmedianGains(s, {0}, cand, cand, 1.0, {1, 2}), std::invalid_argument);
  EXPECT_THROW(kmedianGains(s, {0}, cand, cand, 1.0, std::vector<double>(cand.size(), -1.0)), std::invalid_argument);
  EXPECT_THROW(kmedianGains(s, {0}, cand, cand, 1.0, std::vector<double>(cand.size(), NAN)), std::invalid_argument);
}

// Where FisherRF repeats itself: two near-duplicate views A (x = 6) and A' (6.05) are the
// most uncertain, B (x = -6) a little less. FisherRF takes A, then A' (its score barely
// drops in a trace over its own pixels); with A held, A' brings no view nearer a held one,
// so the weighted gain takes B.
TEST(Selectors, WeightedKmedianDoesNotRepeatANearDuplicate) {
  const Scene s = lineScene({0, 6, 6.05, -6});
  const std::vector<int> cand = {2, 3};  // A (1) already taken
  const std::vector<double> fisher_like = {4.9, 3.0};
  EXPECT_EQ(cand[argmaxScore(fisher_like, cand)], 2);
  const std::vector<double> g = kmedianGains(s, {0, 1}, cand, cand, 1.0, fisher_like);
  EXPECT_EQ(cand[argmaxScore(g, cand)], 3);
  EXPECT_NEAR(g[0], 4.9 * 0.05, 1e-9);
  EXPECT_NEAR(g[1], 3.0 * 6, 1e-9);
}

// The pose distance: the centres' distance plus the angle scale times the angle of the
// optical axes; exact for a pure turn, symmetric, zero for one camera, and accurate for
// nearly parallel axes.
TEST(Selectors, PoseDistanceAddsTheScaledAngleOfTheAxes) {
  const Scene s = ringScene(4);
  const Intrinsics K = s.views[0].camera.K;
  const Camera a = Camera::lookAt(K, Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(1, 7, 3), Eigen::Vector3d::UnitZ());
  const Camera b = Camera::lookAt(K, Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(6, 2, 3), Eigen::Vector3d::UnitZ());
  EXPECT_NEAR(poseDistance(a, b, 2.0), 2.0 * M_PI / 2, 1e-12);
  EXPECT_NEAR(poseDistance(a, b, 2.0), poseDistance(b, a, 2.0), 1e-15);
  EXPECT_EQ(poseDistance(a, a, 2.0), 0.0);
  const Camera c =
      Camera::lookAt(K, Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(1 + 1e-7, 7, 3), Eigen::Vector3d::UnitZ());
  EXPECT_NEAR(poseDistance(a, c, 1.0), 2e-8, 1e-14);  // acos would return 0 or 1e-4 here
  // The ring's radius is its angle scale; a single place falls back to 1.
  EXPECT_NEAR(poseAngleScale(ringScene(12)), 4, 1e-12);
  EXPECT_EQ(poseAngleScale(lineScene({2, 2, 2})), 1);
}

}  // namespace
}  // namespace saresgs

namespace saresgs {
namespace {

// captureClustering on constructed captures: an evenly spaced line (its 5th neighbour is
// 3 to 5 away, nearer only at the ends) is even; two tight crowds with a thin string of
// cameras between them are clustered, on either side of the adaptive selector's default
// threshold; a moved and scaled copy gives the same value (unitless).
TEST(Selectors, CaptureClusteringSeparatesEvenFromClusteredCaptures) {
  std::vector<double> even;
  for (int i = 0; i < 40; ++i) even.push_back(i);
  // The definition written out plainly (sorted distances to every camera, itself first at
  // 0, so index k is the k-th nearest other camera), against the function's nth_element.
  auto cv = [](const std::vector<double>& xs, int k) {
    std::vector<double> kth;
    for (double x : xs) {
      std::vector<double> d;
      for (double y : xs) d.push_back(std::abs(x - y));
      std::sort(d.begin(), d.end());
      kth.push_back(d[static_cast<std::size_t>(k)]);
    }
    double m = 0, v = 0;
    for (double x : kth) m += x / static_cast<double>(kth.size());
    for (double x : kth) v += (x - m) * (x - m) / static_cast<double>(kth.size());
    return std::sqrt(v) / m;
  };
  const double c_even = captureClustering(lineScene(even));
  EXPECT_NEAR(c_even, cv(even, 5), 1e-12);
  EXPECT_LT(c_even, 0.3);
  // Two crowds of 15 (0.01 apart) at 0 and 100, and 10 cameras strung between them.
  std::vector<double> crowds;
  for (int i = 0; i < 15; ++i) crowds.push_back(0.01 * i);
  for (int i = 0; i < 15; ++i) crowds.push_back(100 + 0.01 * i);
  for (int i = 1; i <= 10; ++i) crowds.push_back(9.0 * i);
  const double c_crowds = captureClustering(lineScene(crowds));
  EXPECT_NEAR(c_crowds, cv(crowds, 5), 1e-12);
  EXPECT_GT(c_crowds, 1.0);
  EXPECT_GT(c_crowds, ActiveOptions{}.adaptive_clustering);
  EXPECT_LT(c_even, ActiveOptions{}.adaptive_clustering);
  // Frame and scale free.
  std::vector<double> moved;
  for (double x : crowds) moved.push_back(1e5 + 1e-3 * x);
  EXPECT_NEAR(captureClustering(lineScene(moved)), c_crowds, 1e-6);
  // Degenerate captures: too few cameras, all at one place.
  EXPECT_EQ(captureClustering(lineScene({0, 1, 2, 3, 4})), 0);
  EXPECT_EQ(captureClustering(lineScene(std::vector<double>(10, 3.0))), 0);
}

}  // namespace
}  // namespace saresgs
