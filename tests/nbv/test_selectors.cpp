// Selectors without grids (random, farthest view sampling, argmax and top-N % rules) and
// AUSE against hand-computable cases.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

#include "nbv/ause.h"
#include "nbv/selectors.h"

namespace saresgs {
namespace {

Scene ringScene(int n) {
  Scene s;
  Intrinsics K;
  K.width = 32;
  K.height = 24;
  K.fx = K.fy = 30;
  K.cx = 16;
  K.cy = 12;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    SceneView v;
    v.name = std::to_string(i);
    v.camera = Camera::lookAt(K, Eigen::Vector3d(4 * std::cos(a), 4 * std::sin(a), 0), Eigen::Vector3d::Zero(),
                              Eigen::Vector3d::UnitZ());
    s.views.push_back(v);
    s.train.push_back(i);
  }
  return s;
}

TEST(Selectors, FarthestViewPicksTheOppositeCamera) {
  const Scene s = ringScene(12);
  // Chosen 0 and 1 on a ring of 12; the nearest-chosen distances in steps are
  // 3 -> 2, 5 -> 4, 7 -> 5 (to 0 the other way round), 9 -> 3.
  const std::vector<int> chosen = {0, 1}, cand = {3, 5, 7, 9};
  for (ViewDistance m : {ViewDistance::kEuclidean, ViewDistance::kGreatCircle}) {
    const auto scores = farthestViewScores(s, chosen, cand, m, Eigen::Vector3d::Zero());
    EXPECT_EQ(cand[argmaxScore(scores, cand)], 7) << static_cast<int>(m);
    if (m == ViewDistance::kGreatCircle) EXPECT_NEAR(scores[2], 5 * 2 * M_PI / 12, 1e-12);
    else EXPECT_NEAR(scores[1], 2 * 4 * std::sin(4 * M_PI / 12), 1e-12);  // chord of 4 steps
  }
}

TEST(Selectors, GreatCircleIgnoresRadius) {
  Scene s = ringScene(4);
  // Pull view 2 (opposite) close to the centre along its direction: Euclidean distance to
  // view 0 shrinks, the angle does not.
  s.views[2].camera = Camera::lookAt(s.views[2].camera.K, Eigen::Vector3d(-0.5, 0, 0), Eigen::Vector3d(1, 0, 0),
                                     Eigen::Vector3d::UnitZ());
  const std::vector<int> cand = {1, 2};
  EXPECT_EQ(cand[argmaxScore(farthestViewScores(s, {0}, cand, ViewDistance::kGreatCircle, Eigen::Vector3d::Zero()), cand)], 2);
  EXPECT_EQ(cand[argmaxScore(farthestViewScores(s, {0}, cand, ViewDistance::kEuclidean, Eigen::Vector3d::Zero()), cand)], 1);
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
