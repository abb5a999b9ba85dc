#include <gtest/gtest.h>

#include <random>

#include "nbv/initial_views.h"

using namespace saresgs;

TEST(InitialViews, PicksTheExtremesOfALine) {
  std::vector<Eigen::Vector3d> c;
  for (int i = 0; i < 11; ++i) c.emplace_back(i, 0, 0);
  const auto s = farthestPointSampling(c, 3, 0);
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(s[0], 0);
  EXPECT_EQ(s[1], 10);
  EXPECT_EQ(s[2], 5);
}

TEST(InitialViews, EachPickMaximisesTheDistanceToThoseBefore) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0, 1);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Eigen::Vector3d> c(60);
    for (auto& p : c) p = Eigen::Vector3d(n(rng), n(rng), n(rng));
    const auto s = farthestPointSampling(c, 8, trial % 60);
    ASSERT_EQ(s.size(), 8u);
    EXPECT_EQ(s[0], trial % 60);
    for (size_t k = 1; k < s.size(); ++k) {
      // Brute force: the largest distance-to-chosen over all points.
      auto dmin = [&](int i) {
        double d = 1e300;
        for (size_t j = 0; j < k; ++j) d = std::min(d, (c[i] - c[s[j]]).norm());
        return d;
      };
      double best = 0;
      for (int i = 0; i < 60; ++i) best = std::max(best, dmin(i));
      EXPECT_DOUBLE_EQ(dmin(s[k]), best);
    }
  }
}

TEST(InitialViews, DuplicateCentresAndSmallSets) {
  std::vector<Eigen::Vector3d> same(5, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(farthestPointSampling(same, 4, 0).size(), 1u);  // nothing farther than 0
  EXPECT_TRUE(farthestPointSampling({}, 4, 0).empty());
  std::vector<Eigen::Vector3d> two = {{0, 0, 0}, {1, 0, 0}};
  EXPECT_EQ(farthestPointSampling(two, 4, 1), (std::vector<int>{1, 0}));
  EXPECT_THROW(farthestPointSampling(two, 2, 5), std::out_of_range);
}
