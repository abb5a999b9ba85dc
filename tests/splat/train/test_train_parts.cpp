// The trainer's parts against independent oracles: nearest-neighbour scales against
// brute force, Adam against a double-precision scalar formula, densification against
// hand-built cases and the split's sampling covariance, the residual subset's counts.
#include <gtest/gtest.h>

#include <bit>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <iterator>
#include <random>
#include <set>

#include "splat/train/adam.h"
#include "tests/splat/gaussians_bits.h"
#include "splat/train/densify.h"
#include "splat/train/init.h"
#include "splat/train/residual.h"

namespace saresgs {
namespace {

double bruteMeanSq(const std::vector<Eigen::Vector3d>& p, std::size_t i, int k) {
  std::vector<double> d;
  for (std::size_t j = 0; j < p.size(); ++j)
    if (j != i) d.push_back((p[j] - p[i]).squaredNorm());
  std::sort(d.begin(), d.end());
  const std::size_t kk = std::min<std::size_t>(static_cast<std::size_t>(k), d.size());
  double s = 0;
  for (std::size_t j = 0; j < kk; ++j) s += d[j];
  return std::max(s / static_cast<double>(kk), 1e-7);
}

TEST(TrainInit, KnnDistancesMatchBruteForce) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> nd(0, 1);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 4; ++trial) {
    std::vector<Eigen::Vector3d> p;
    const int n = 400 + 300 * trial;
    for (int i = 0; i < n; ++i) {
      if (trial == 1)
        p.emplace_back(u(rng) * 10, 0.0, 0.0);  // a line: flat box
      else if (trial == 2)
        p.emplace_back(nd(rng), nd(rng), 1e-3 * nd(rng));  // a thin sheet
      else
        p.emplace_back(nd(rng) * (i % 10 == 0 ? 20 : 1), nd(rng), nd(rng));  // clusters + outliers
    }
    if (trial == 3) p.push_back(p[0]), p.push_back(p[0]);  // duplicates
    const auto d = meanSquaredKnnDistance(p);
    for (std::size_t i = 0; i < p.size(); ++i)
      ASSERT_NEAR(d[i], bruteMeanSq(p, i, 3), 1e-12 * (1 + d[i])) << trial << " " << i;
  }
  EXPECT_EQ(meanSquaredKnnDistance({Eigen::Vector3d(1, 2, 3)}).at(0), 1e-7);
  const auto two = meanSquaredKnnDistance({Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 3, 4)});
  EXPECT_DOUBLE_EQ(two[0], 25.0);  // fewer than 3 neighbours: the mean over those there are
}

TEST(TrainInit, GaussiansFromPointsFollowTheReferenceInit) {
  std::vector<ColoredPoint> pts = {{Eigen::Vector3d(0, 0, 0), {1.0f, 0.5f, 0.0f}},
                                   {Eigen::Vector3d(1, 0, 0), {0.2f, 0.2f, 0.2f}},
                                   {Eigen::Vector3d(0, 2, 0), {0, 0, 0}},
                                   {Eigen::Vector3d(0, 0, 3), {0, 0, 0}}};
  const Gaussians g = gaussiansFromPoints(pts, 2);
  ASSERT_EQ(g.size(), 4u);
  EXPECT_EQ(g.shCoeffs(), 9);
  // Point 0's neighbours are at 1, 2, 3: mean squared distance 14/3.
  EXPECT_NEAR(g.log_scales[0], 0.5 * std::log(14.0 / 3.0), 1e-6);
  EXPECT_EQ(g.log_scales[0], g.log_scales[1]);
  EXPECT_NEAR(1 / (1 + std::exp(-g.opacities[0])), 0.1, 1e-6);
  EXPECT_EQ(g.rotations[0], 1.0f);
  EXPECT_NEAR(g.sh[0] * kShC0 + 0.5, 1.0, 1e-6);
  EXPECT_NEAR(g.sh[1] * kShC0 + 0.5, 0.5, 1e-6);
  for (int k = 3; k < 27; ++k) EXPECT_EQ(g.sh[k], 0.0f);
  EXPECT_THROW(gaussiansFromPoints({}, 0), std::invalid_argument);
}

// n Gaussians at SH degree `degree` with every value drawn from `nd` (the Adam tests' model).
Gaussians normalModel(int degree, std::size_t n, std::mt19937_64& rng, std::normal_distribution<float>& nd) {
  Gaussians p;
  p.max_sh_degree = degree;
  p.resize(n);
  p.forEachArray([&](std::vector<float>& a, std::size_t) {
    for (float& x : a) x = nd(rng);
  });
  return p;
}

TEST(TrainAdam, MatchesTheScalarFormulaInDouble) {
  std::mt19937_64 rng(9);
  std::normal_distribution<float> nd(0, 1);
  Gaussians p = normalModel(1, 7, rng, nd);
  const Gaussians p0 = p;
  AdamState st;
  st.resetFor(p);
  LearningRates lr;
  lr.means = 0.01f;
  std::vector<Gaussians> grads;
  for (int t = 0; t < 4; ++t) {
    Gaussians g = p.zerosLike();
    g.forEachArray([&](std::vector<float>& a, std::size_t) {
      for (float& x : a) x = nd(rng) * (t == 2 ? 1e-4f : 1.0f);
    });
    grads.push_back(g);
    adamStep(p, g, st, lr);
  }
  EXPECT_EQ(st.step, 4);
  // sh entry (Gaussian 3, coefficient 2, channel 1) uses the SH-rest rate; entry 0 the DC rate.
  auto check = [&](const std::vector<float>& (*pick)(const Gaussians&), std::size_t idx, double rate) {
    double x = pick(p0)[idx], m = 0, v = 0;
    for (int t = 1; t <= 4; ++t) {
      const double gi = pick(grads[t - 1])[idx];
      m = 0.9 * m + 0.1 * gi;
      v = 0.999 * v + 0.001 * gi * gi;
      const double mh = m / (1 - std::pow(0.9, t)), vh = v / (1 - std::pow(0.999, t));
      x -= rate * mh / (std::sqrt(vh) + 1e-15);
    }
    EXPECT_NEAR(pick(p)[idx], x, 1e-5 * (1 + std::abs(x))) << idx;
  };
  check([](const Gaussians& g) -> const std::vector<float>& { return g.means; }, 5, 0.01);
  check([](const Gaussians& g) -> const std::vector<float>& { return g.log_scales; }, 4, 5e-3);
  check([](const Gaussians& g) -> const std::vector<float>& { return g.rotations; }, 9, 1e-3);
  check([](const Gaussians& g) -> const std::vector<float>& { return g.opacities; }, 6, 5e-2);
  check([](const Gaussians& g) -> const std::vector<float>& { return g.sh; }, 3 * 12 + 0, 2.5e-3);
  check([](const Gaussians& g) -> const std::vector<float>& { return g.sh; }, 3 * 12 + 2 * 3 + 1, 2.5e-3 / 20);
}

// At SH degree 3 (48 values per Gaussian: the DC rate for 3, the rest rate for 45, one
// loop per row) and on every array, adamStep's vectorised loops (AVX2 where the CPU has it)
// give the float formula's values bit for bit, value by value.
TEST(TrainAdam, EveryValueIsTheFloatFormulaBitForBit) {
  std::mt19937_64 rng(12);
  std::normal_distribution<float> nd(0, 1);
  Gaussians p = normalModel(3, 37, rng, nd);
  const Gaussians initial = p;
  Gaussians want = p;
  AdamState st, ref;
  st.resetFor(p);
  ref.resetFor(p);
  LearningRates lr;
  for (int t = 1; t <= 3; ++t) {
    Gaussians g = p.zerosLike();
    g.forEachArray([&](std::vector<float>& a, std::size_t) {
      for (float& x : a) x = nd(rng) * (t == 2 ? 1e-3f : 1.0f);
    });
    adamStep(p, g, st, lr);
    const float inv_bc1 = static_cast<float>(1.0 / (1.0 - std::pow(static_cast<double>(ref.beta1), t)));
    const float inv_sqrt_bc2 = static_cast<float>(1.0 / std::sqrt(1.0 - std::pow(static_cast<double>(ref.beta2), t)));
    auto update = [&](std::vector<float>& x, const std::vector<float>& gr, std::vector<float>& m, std::vector<float>& v,
                      std::size_t per, std::size_t head, float lr_head, float lr_tail) {
      for (std::size_t i = 0; i < x.size(); ++i) {
        const float step = (i % per < head ? lr_head : lr_tail) * inv_bc1;
        const float mi = ref.beta1 * m[i] + (1.0f - ref.beta1) * gr[i];
        const float vi = ref.beta2 * v[i] + (1.0f - ref.beta2) * gr[i] * gr[i];
        m[i] = mi;
        v[i] = vi;
        x[i] -= step * mi / (std::sqrt(vi) * inv_sqrt_bc2 + ref.eps);
      }
    };
    update(want.means, g.means, ref.m.means, ref.v.means, 3, 3, lr.means, lr.means);
    update(want.log_scales, g.log_scales, ref.m.log_scales, ref.v.log_scales, 3, 3, lr.log_scales, lr.log_scales);
    update(want.rotations, g.rotations, ref.m.rotations, ref.v.rotations, 4, 4, lr.rotations, lr.rotations);
    update(want.opacities, g.opacities, ref.m.opacities, ref.v.opacities, 1, 1, lr.opacities, lr.opacities);
    update(want.sh, g.sh, ref.m.sh, ref.v.sh, 48, 3, lr.sh_dc, lr.sh_rest);
  }
  EXPECT_TRUE(test::arraysBitEqual(p, want));
  for (std::size_t k = 0; k < p.sh.size(); ++k) EXPECT_NE(p.sh[k], initial.sh[k]) << k;  // every value moved
}

// adamStepClearingGradient is adamStep (the same parameters and moments, bit for bit) that
// leaves the gradient zero, at every SH degree's row length.
TEST(TrainAdam, ClearingStepEqualsTheStepAndZeroesTheGradient) {
  for (int degree = 0; degree <= 3; ++degree) {
    std::mt19937_64 rng(20 + degree);
    std::normal_distribution<float> nd(0, 1);
    Gaussians p = normalModel(degree, 2100, rng, nd);  // more than one block of the parallel loop
    Gaussians q = p;
    AdamState a, b;
    a.resetFor(p);
    b.resetFor(p);
    for (int t = 0; t < 2; ++t) {
      Gaussians g = p.zerosLike();
      g.forEachArray([&](std::vector<float>& x, std::size_t) {
        for (float& v : x) v = nd(rng);
      });
      Gaussians h = g;
      adamStep(p, g, a, LearningRates{});
      adamStepClearingGradient(q, h, b, LearningRates{});
      h.forEachArray([&](const std::vector<float>& x, std::size_t) {
        for (const float v : x) ASSERT_EQ(std::bit_cast<std::uint32_t>(v), 0u);
      });
    }
    EXPECT_TRUE(test::arraysBitEqual(q, p)) << "degree " << degree;
    EXPECT_TRUE(test::arraysBitEqual(b.m, a.m)) << "degree " << degree;
    EXPECT_TRUE(test::arraysBitEqual(b.v, a.v)) << "degree " << degree;
  }
}

// Four Gaussians: 0 small with a large gradient (clone), 1 large with a large gradient
// (split), 2 small gradient (kept), 3 nearly transparent (pruned).
struct DensifyCase {
  Gaussians g;
  AdamState adam;
  DensifyStats st;
  DensifyOptions opt;
  double extent = 10;
  DensifyCase() {
    g.resize(4);
    for (int i = 0; i < 4; ++i) {
      g.means[3 * i] = static_cast<float>(i);
      g.rotations[4 * i] = 1;
      g.opacities[i] = 0.0f;
      g.sh[3 * i] = 0.1f * i;
      for (int k = 0; k < 3; ++k) g.log_scales[3 * i + k] = std::log(0.05f);  // 0.05 < 0.01 * 10
    }
    for (int k = 0; k < 3; ++k) g.log_scales[3 + k] = std::log(0.5f);
    g.opacities[3] = std::log(0.001f / 0.999f);
    adam.resetFor(g);
    for (int i = 0; i < 4; ++i) adam.m.opacities[i] = adam.v.opacities[i] = 1.0f + i;
    st.resize(4);
    const float grads[4] = {3e-4f, 5e-4f, 1e-4f, 1e-4f};
    for (int i = 0; i < 4; ++i) {
      st.grad_accum[i] = 2 * grads[i];
      st.count[i] = 2;
    }
  }
};

TEST(TrainDensify, ClonesSmallSplitsLargePrunesTransparent) {
  DensifyCase c;
  std::mt19937_64 rng(1);
  const DensifyReport r = densifyAndPrune(c.g, c.adam, c.st, c.opt, c.extent, false, rng);
  EXPECT_EQ(r.cloned, 1u);
  EXPECT_EQ(r.split, 1u);
  EXPECT_EQ(r.pruned, 1u);
  // Kept: 0, 2, clone of 0, two children of 1.
  ASSERT_EQ(c.g.size(), 5u);
  EXPECT_EQ(c.g.means[0], 0.0f);
  EXPECT_EQ(c.g.means[3], 2.0f);
  EXPECT_EQ(c.g.means[6], 0.0f);
  EXPECT_EQ(c.g.sh[6], 0.0f);
  for (int j = 3; j < 5; ++j) {
    EXPECT_NEAR(c.g.log_scales[3 * j], std::log(0.5f / 1.6f), 1e-6);
    EXPECT_NE(c.g.means[3 * j], 1.0f);  // moved by a sample
    EXPECT_NEAR(c.g.sh[3 * j], 0.1f, 1e-7);
  }
  // Moments follow their Gaussians; new ones start at zero.
  EXPECT_EQ(c.adam.m.opacities, (std::vector<float>{1, 3, 0, 0, 0}));
  EXPECT_EQ(c.st.count, std::vector<std::int32_t>(5, 0));
}

TEST(TrainDensify, BigPruningOnlyWhenAsked) {
  for (bool prune_big : {false, true}) {
    DensifyCase c;
    c.st.grad_accum.assign(4, 0.0f);     // nothing densifies
    c.st.max_radius = {30, 1, 1, 1};     // Gaussian 0 is big on screen
    c.g.log_scales[6] = std::log(2.0f);  // Gaussian 2 is big in the world (> 0.1 * 10)
    std::mt19937_64 rng(1);
    densifyAndPrune(c.g, c.adam, c.st, c.opt, c.extent, prune_big, rng);
    EXPECT_EQ(c.g.size(), prune_big ? 1u : 3u);
  }
}

TEST(TrainDensify, SplitSamplesFollowTheRotatedCovariance) {
  Gaussians g;
  g.resize(1);
  const Eigen::Quaternionf q = Eigen::Quaternionf(Eigen::AngleAxisf(0.7f, Eigen::Vector3f(1, 2, 3).normalized()));
  g.rotations = {2 * q.w(), 2 * q.x(), 2 * q.y(), 2 * q.z()};  // unnormalised on purpose
  g.log_scales = {std::log(0.3f), std::log(0.1f), std::log(0.02f)};
  g.opacities = {0};
  AdamState adam;
  adam.resetFor(g);
  DensifyStats st;
  st.resize(1);
  st.grad_accum = {1};
  st.count = {1};
  DensifyOptions opt;
  opt.split_count = 20000;
  std::mt19937_64 rng(2);
  densifyAndPrune(g, adam, st, opt, 1.0, false, rng);
  ASSERT_EQ(g.size(), 20000u);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Eigen::Vector3d p(g.means[3 * i], g.means[3 * i + 1], g.means[3 * i + 2]);
    cov += p * p.transpose();
  }
  cov /= static_cast<double>(g.size());
  const Eigen::Matrix3d R = q.toRotationMatrix().cast<double>();
  const Eigen::Matrix3d expect = R * Eigen::Vector3d(0.09, 0.01, 0.0004).asDiagonal() * R.transpose();
  EXPECT_LT((cov - expect).norm(), 0.03 * expect.norm()) << cov << "\nvs\n" << expect;
}

TEST(TrainDensify, CapLimitsGrowthAndOpacityResetZeroesItsMoments) {
  DensifyCase c;
  c.opt.max_gaussians = 4;
  std::mt19937_64 rng(1);
  const DensifyReport r = densifyAndPrune(c.g, c.adam, c.st, c.opt, c.extent, false, rng);
  EXPECT_EQ(r.cloned + r.split, 0u);
  EXPECT_LE(c.g.size(), 4u);
  resetOpacity(c.g, c.adam);
  for (std::size_t i = 0; i < c.g.size(); ++i) EXPECT_LE(1 / (1 + std::exp(-c.g.opacities[i])), 0.01f + 1e-7f);
  for (float m : c.adam.m.opacities) EXPECT_EQ(m, 0.0f);
}

// The brute-force reading of the cap: candidates by mean gradient (ties to the lower
// index), best first, kept while their added Gaussians fit.
std::pair<std::vector<int>, std::vector<int>> keptByBruteForce(const std::vector<int>& clone,
                                                               const std::vector<int>& split,
                                                               const std::vector<float>& grad, std::size_t room,
                                                               int split_count) {
  std::vector<std::pair<int, bool>> all;
  for (int i : clone) all.push_back({i, false});
  for (int i : split) all.push_back({i, true});
  std::sort(all.begin(), all.end(), [&](const auto& a, const auto& b) {
    return grad[a.first] != grad[b.first] ? grad[a.first] > grad[b.first] : a.first < b.first;
  });
  std::vector<int> kc, ks;
  std::size_t used = 0;
  for (const auto& [i, is_split] : all) {
    const std::size_t cost = is_split ? static_cast<std::size_t>(split_count - 1) : 1;
    if (used + cost > room) break;
    used += cost;
    (is_split ? ks : kc).push_back(i);
  }
  std::sort(kc.begin(), kc.end());
  std::sort(ks.begin(), ks.end());
  return {kc, ks};
}

TEST(TrainDensify, CapKeepsTheCandidatesWithTheLargestGradients) {
  std::mt19937_64 rng(12);
  std::uniform_int_distribution<int> coarse(0, 20);  // many ties
  for (int split_count : {2, 3}) {
    for (int trial = 0; trial < 20; ++trial) {
      const std::size_t n = 300;
      std::vector<float> grad(n);
      for (float& x : grad) x = 1e-4f * static_cast<float>(coarse(rng));
      std::vector<int> clone, split;
      for (std::size_t i = 0; i < n; ++i)
        if (grad[i] >= 5e-4f) (i % 3 ? clone : split).push_back(static_cast<int>(i));
      for (std::size_t room : {std::size_t{0}, std::size_t{1}, std::size_t{37}, std::size_t{150}, std::size_t{1000}}) {
        DensifyOptions opt;
        opt.split_count = split_count;
        opt.max_gaussians = n + room;
        std::vector<int> c = clone, s = split;
        keepLargestGradients(c, s, grad, n, opt);
        const auto [bc, bs] = keptByBruteForce(clone, split, grad, room, split_count);
        EXPECT_EQ(c, bc) << "room " << room << " split_count " << split_count;
        EXPECT_EQ(s, bs) << "room " << room << " split_count " << split_count;
        const std::size_t added = c.size() + s.size() * static_cast<std::size_t>(split_count - 1);
        EXPECT_LE(added, room);
        if (room >= clone.size() + split.size() * static_cast<std::size_t>(split_count - 1)) {
          EXPECT_EQ(c, clone);  // no cap binds: everything kept
          EXPECT_EQ(s, split);
        }
      }
    }
  }
}

TEST(TrainDensify, CapInTheModelKeepsTheHighestGradientGaussiansGrowing) {
  // Ten small Gaussians, all over the threshold, gradients rising with the index; room for
  // three clones: the three last are cloned (index order did not decide).
  Gaussians g;
  g.resize(10);
  for (std::size_t i = 0; i < 10; ++i) {
    g.means[3 * i] = static_cast<float>(i);
    for (int a = 0; a < 3; ++a) g.log_scales[3 * i + a] = std::log(0.001f);
    g.opacities[i] = 2.0f;
    g.rotations[4 * i] = 1.0f;
  }
  AdamState adam;
  adam.resetFor(g);
  DensifyStats st;
  st.resize(10);
  for (std::size_t i = 0; i < 10; ++i) {
    st.grad_accum[i] = 1e-3f * static_cast<float>(i + 1);
    st.count[i] = 1;
  }
  DensifyOptions opt;
  opt.max_gaussians = 13;
  std::mt19937_64 rng(3);
  const DensifyReport r = densifyAndPrune(g, adam, st, opt, 10.0, false, rng);
  EXPECT_EQ(r.cloned, 3u);
  ASSERT_EQ(g.size(), 13u);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(g.means[3 * (10 + k)], static_cast<float>(7 + k)) << k;
}

Gaussians rankedModel(int n) {
  Gaussians g;
  g.resize(n);
  for (int i = 0; i < n; ++i) {
    g.opacities[i] = static_cast<float>(i);                  // lowest opacity: low indices
    g.log_scales[3 * i + (i % 3)] = static_cast<float>(-i);  // largest scale: low indices too...
  }
  // ...so make the scale ranking distinct: reverse it for the upper half.
  for (int i = n / 2; i < n; ++i) g.log_scales[3 * i + (i % 3)] = static_cast<float>(i);
  return g;
}

TEST(TrainResidual, SubsetHoldsExactProportionsAndTheIntendedGaussians) {
  const int n = 1000;
  const Gaussians g = rankedModel(n);
  ResidualOptions o;
  std::mt19937_64 rng(4);
  const ResidualSubset s = selectResidualSubset(g, o, rng);
  EXPECT_EQ(s.random.size(), 900u);
  EXPECT_EQ(std::set<int>(s.random.begin(), s.random.end()).size(), 900u);
  // Lowest opacity: 0..99; largest scale: 999 down to 900. Union of both.
  std::vector<int> expect;
  for (int i = 0; i < 100; ++i) expect.push_back(i);
  for (int i = 900; i < 1000; ++i) expect.push_back(i);
  EXPECT_EQ(s.uncertain, expect);
  std::size_t in = 0;
  for (int i = 0; i < n; ++i) {
    const bool want =
        std::binary_search(s.random.begin(), s.random.end(), i) || std::binary_search(expect.begin(), expect.end(), i);
    EXPECT_EQ(s.mask[i], want ? 1 : 0);
    in += s.mask[i];
  }
  EXPECT_GT(in, 900u);
  EXPECT_LE(in, 1000u);

  o.ranking = UncertaintyRanking::kOpacity;  // beta doubled: 0..199
  const ResidualSubset so = selectResidualSubset(g, o, rng);
  ASSERT_EQ(so.uncertain.size(), 200u);
  EXPECT_EQ(so.uncertain.front(), 0);
  EXPECT_EQ(so.uncertain.back(), 199);
  o.ranking = UncertaintyRanking::kScale;  // 800..999
  const ResidualSubset ss = selectResidualSubset(g, o, rng);
  ASSERT_EQ(ss.uncertain.size(), 200u);
  EXPECT_EQ(ss.uncertain.front(), 800);
  o.ranking = UncertaintyRanking::kRandom;
  EXPECT_EQ(selectResidualSubset(g, o, rng).uncertain.size(), 200u);
  EXPECT_THROW(parseUncertaintyRanking("loud"), std::invalid_argument);
  EXPECT_TRUE(selectResidualSubset(Gaussians{}, o, rng).mask.empty());
}

TEST(TrainResidual, SameGeneratorStateSameSubset) {
  const Gaussians g = rankedModel(300);
  ResidualOptions o;
  std::mt19937_64 a(11), b(11);
  EXPECT_EQ(selectResidualSubset(g, o, a).mask, selectResidualSubset(g, o, b).mask);
  EXPECT_NE(selectResidualSubset(g, o, a).random, selectResidualSubset(g, o, a).random);
}

// selectResidualSubset's definition restated plainly: the partial Fisher-Yates draw, and
// the rankings as a full stable sort by key (ties by index).
ResidualSubset referenceSubset(const Gaussians& g, const ResidualOptions& o, std::uint64_t seed) {
  const std::size_t n = g.size();
  std::mt19937_64 rng(seed);
  auto countOf = [&](double f) {
    return std::min(n, static_cast<std::size_t>(std::llround(std::clamp(f, 0.0, 1.0) * static_cast<double>(n))));
  };
  ResidualSubset r;
  std::vector<int> idx(n);
  std::iota(idx.begin(), idx.end(), 0);
  const std::size_t k = countOf(o.alpha);
  for (std::size_t i = 0; i < k; ++i) {
    std::uniform_int_distribution<std::size_t> pick(i, n - 1);
    std::swap(idx[i], idx[pick(rng)]);
  }
  r.random.assign(idx.begin(), idx.begin() + static_cast<std::ptrdiff_t>(k));
  std::sort(r.random.begin(), r.random.end());
  auto top = [&](double fraction, auto key) {
    std::vector<int> all(n);
    std::iota(all.begin(), all.end(), 0);
    std::stable_sort(all.begin(), all.end(), [&](int a, int b) { return key(a) < key(b); });
    std::vector<int> t(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(countOf(fraction)));
    std::sort(t.begin(), t.end());
    return t;
  };
  auto opacity = [&](int i) { return std::isnan(g.opacities[i]) ? -INFINITY : g.opacities[i]; };
  auto scale = [&](int i) {
    const float s = std::max({g.log_scales[3 * i], g.log_scales[3 * i + 1], g.log_scales[3 * i + 2]});
    return std::isnan(s) ? -INFINITY : -s;
  };
  if (o.ranking == UncertaintyRanking::kBoth) {
    const auto a = top(o.beta, opacity), b = top(o.beta, scale);
    std::set_union(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(r.uncertain));
  } else if (o.ranking == UncertaintyRanking::kOpacity) {
    r.uncertain = top(2 * o.beta, opacity);
  } else if (o.ranking == UncertaintyRanking::kScale) {
    r.uncertain = top(2 * o.beta, scale);
  }
  r.mask.assign(n, 0);
  for (int i : r.random) r.mask[i] = 1;
  for (int i : r.uncertain) r.mask[i] = 1;
  return r;
}

void expectSubsetIsItsDefinition(const Gaussians& g, const ResidualOptions& o, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const ResidualSubset s = selectResidualSubset(g, o, rng);
  const ResidualSubset r = referenceSubset(g, o, seed);
  EXPECT_EQ(s.random, r.random);
  EXPECT_EQ(s.uncertain, r.uncertain);
  EXPECT_EQ(s.mask, r.mask);
}

// selectResidualSubset against the plain restatement above, on keys with many ties and a
// NaN, negative and positive keys, both zeros and infinities, so a faster selection
// cannot change which Gaussians train.
TEST(TrainResidual, SubsetEqualsItsDefinition) {
  const std::size_t n = 2000;
  Gaussians g = rankedModel(static_cast<int>(n));
  for (std::size_t i = 0; i < n; ++i) {
    g.opacities[i] = static_cast<float>(i % 17) - 8.0f;  // ties, both signs
    for (int k = 0; k < 3; ++k) g.log_scales[3 * i + k] = static_cast<float>((i * (k + 3)) % 23) - 11.0f;
  }
  g.opacities[77] = NAN;
  for (std::size_t i = 5; i < n; i += 97) g.opacities[i] = (i / 97) % 2 ? -0.0f : 0.0f;  // ties of -0 and +0
  g.opacities[300] = -INFINITY;
  g.opacities[301] = INFINITY;
  g.log_scales[3 * 400 + 1] = INFINITY;
  ResidualOptions o;
  expectSubsetIsItsDefinition(g, o, 5);
  for (const UncertaintyRanking r : {UncertaintyRanking::kOpacity, UncertaintyRanking::kScale}) {
    o.ranking = r;
    expectSubsetIsItsDefinition(g, o, 6);
  }
}

// The ranking selects by radix digits of the keys (splat/train/residual.cpp): models past
// 2^16 Gaussians (index digits above the lowest ones), keys all equal (the initial model's
// opacities: every digit of the key is shared, only the index tells them apart), keys in
// one narrow band, and fractions that select none, half and all.
TEST(TrainResidual, SubsetEqualsItsDefinitionAtScaleAndOnEqualKeys) {
  std::mt19937 gen(3);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  Gaussians big = rankedModel(70000);
  for (std::size_t i = 0; i < big.size(); ++i) {
    big.opacities[i] = 3.0f * normal(gen);
    for (int k = 0; k < 3; ++k) big.log_scales[3 * i + k] = -4.0f + 1.5f * normal(gen);
  }
  ResidualOptions o;
  expectSubsetIsItsDefinition(big, o, 7);

  Gaussians same = rankedModel(5000);
  for (std::size_t i = 0; i < same.size(); ++i) {
    same.opacities[i] = -2.1972246f;  // logit 0.1
    for (int k = 0; k < 3; ++k) same.log_scales[3 * i + k] = -3.0f;
  }
  expectSubsetIsItsDefinition(same, o, 8);

  Gaussians band = rankedModel(9000);
  for (std::size_t i = 0; i < band.size(); ++i) {
    band.opacities[i] = 1.0f + 1e-6f * static_cast<float>((i * 7919) % 13);  // a few ulps apart
    for (int k = 0; k < 3; ++k) band.log_scales[3 * i + k] = std::nextafter(-1.0f, 0.0f) * ((i + k) % 2 ? 1.0f : -1.0f);
  }
  for (const double beta : {0.0, 0.25, 0.5, 1.0}) {
    o.beta = beta;
    for (const UncertaintyRanking r :
         {UncertaintyRanking::kBoth, UncertaintyRanking::kOpacity, UncertaintyRanking::kScale}) {
      o.ranking = r;
      expectSubsetIsItsDefinition(band, o, 9);
    }
  }
}

}  // namespace
}  // namespace saresgs
