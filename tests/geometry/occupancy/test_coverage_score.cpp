// Hashed vs exact encodings, scores and the top-N % prefilter.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>

#include "common/test_support.h"
#include "geometry/occupancy/candidate_sets.h"
#include "geometry/occupancy/coverage_score.h"
#include "occupancy_test_support.h"

using namespace saresgs;

namespace {

// n distinct random voxels in a large box (random coordinates: the regime where the
// spatial hash should behave like a random function).
VoxelSet randomVoxelSet(std::mt19937_64& rng, std::size_t n) {
  std::uniform_int_distribution<int> c(-4000, 4000);
  std::set<Voxel> s;
  while (s.size() < n) s.insert({c(rng), c(rng), c(rng)});
  return VoxelSet::fromVoxels(std::vector<Voxel>(s.begin(), s.end()));
}

// Occupancy of T buckets by n balls thrown independently and uniformly:
// E = T (1 - q^n), Var = T (T-1) (1-2/T)^n + T q^n - T^2 q^{2n}, q = 1 - 1/T.
double expectedOccupied(double n, double T) { return T * (1.0 - std::pow(1.0 - 1.0 / T, n)); }
double varianceOccupied(double n, double T) {
  const double q = 1.0 - 1.0 / T;
  return T * (T - 1) * std::pow(1.0 - 2.0 / T, n) + T * std::pow(q, n) - T * T * std::pow(q, 2 * n);
}

// Expected hashed scores under a random hash, from the exact set sizes: a = |O \ C|,
// b = |C \ O|, c = |O & C|. A bucket is in b_O XOR b_C when no common voxel hits it and
// exactly one of the two private parts does; it is "new" when C \ O hits it and O
// does not.
double expectedXor(double a, double b, double c, double T) {
  const double q = 1.0 - 1.0 / T;
  const double qa = std::pow(q, a), qb = std::pow(q, b), qc = std::pow(q, c);
  return T * qc * ((1 - qa) * qb + qa * (1 - qb));
}
double expectedNew(double a, double b, double c, double T) {
  const double q = 1.0 - 1.0 / T;
  return T * (1 - std::pow(q, b)) * std::pow(q, a + c);
}

}  // namespace

TEST(SpatialHash, FormulaAndRange) {
  // h(x) = (x0 * 1 XOR x1 * 2654435761 XOR x2 * 805459861) mod T, uint32 arithmetic.
  EXPECT_EQ(spatialHash({0, 0, 0}, 1u << 19), 0u);
  EXPECT_EQ(spatialHash({5, 0, 0}, 1u << 19), 5u);
  EXPECT_EQ(spatialHash({0, 1, 0}, 1u << 19), 2654435761u % (1u << 19));
  EXPECT_EQ(spatialHash({0, 0, 1}, 1u << 11), 805459861u % (1u << 11));
  const std::uint32_t y = 3, z = 7;
  EXPECT_EQ(spatialHash({1, 3, 7}, 1u << 16), (1u ^ (y * 2654435761u) ^ (z * 805459861u)) % (1u << 16));
  // Against the formula in 64-bit arithmetic reduced mod 2^32, then mod T, for random
  // voxels (negative ones too) and every table size of the paper's ablation.
  std::mt19937_64 rng(20);
  std::uniform_int_distribution<int> c(-300000, 300000);
  for (int log2T = 11; log2T <= 19; ++log2T)
    for (int i = 0; i < 2000; ++i) {
      const Voxel v{c(rng), c(rng), c(rng)};
      const auto u32 = [](std::int64_t x) { return static_cast<std::uint64_t>(x) & 0xFFFFFFFFull; };
      const std::uint64_t h = (u32(v[0]) * 1ull % (1ull << 32)) ^ (u32(v[1]) * 2654435761ull % (1ull << 32)) ^
                              (u32(v[2]) * 805459861ull % (1ull << 32));
      ASSERT_EQ(spatialHash(v, 1u << log2T), h % (1ull << log2T));
    }
  // Negative coordinates wrap as uint32.
  EXPECT_EQ(spatialHash({-1, 0, 0}, 1u << 13), (1u << 13) - 1);
  EXPECT_TRUE(test::throwsInputError([] { HashedBits b(1000); }, "hash encoding", "table_size"));
  EXPECT_TRUE(test::throwsInputError([] { HashedBits b(1); }, "hash encoding", "table_size"));
  EXPECT_TRUE(
      test::throwsInputError([] { scoreHashed(HashedBits(64), HashedBits(128)); }, "hash encoding", "table_size"));
}

TEST(Scores, ExactScoresAreSetSizes) {
  std::mt19937_64 rng(21);
  const VoxelSet obs = randomVoxelSet(rng, 500);
  VoxelSet cand = randomVoxelSet(rng, 300);
  const std::vector<Voxel> ov = obs.voxels();
  cand = setUnion(cand, VoxelSet::fromVoxels(std::vector<Voxel>(ov.begin(), ov.begin() + 120)));
  const CoverageScore s = scoreExact(obs, cand, 10000);
  EXPECT_EQ(s.new_count, setDifference(cand, obs).size());
  EXPECT_EQ(s.new_count, 300u);
  EXPECT_EQ(s.differing, setDifference(cand, obs).size() + setDifference(obs, cand).size());
  EXPECT_EQ(s.differing, 300u + 380u);
  EXPECT_DOUBLE_EQ(s.hamming, 680.0 / 10000);
  // Empty universe, empty sets: zeros, never NaN.
  const CoverageScore z = scoreExact({}, {}, 0);
  EXPECT_EQ(z.hamming, 0.0);
  EXPECT_EQ(z.differing, 0u);
  EXPECT_EQ(scoreExact(obs, {}, 0).hamming, 0.0);
  const CoverageScore zh = scoreHashed(HashedBits(1u << 11), HashedBits(1u << 11));
  EXPECT_EQ(zh.hamming, 0.0);
  EXPECT_EQ(zh.new_count, 0u);
}

TEST(Scores, HashedScoresEqualBitSetsOfTheHashes) {
  // The hashed score is the set computation on bucket sets (independent check).
  std::mt19937_64 rng(22);
  const VoxelSet obs = randomVoxelSet(rng, 3000), cand = randomVoxelSet(rng, 2000);
  for (std::size_t T : {std::size_t{1} << 11, std::size_t{1} << 15}) {
    std::set<std::uint32_t> bo, bc;
    for (const Voxel& v : obs.voxels()) bo.insert(spatialHash(v, static_cast<std::uint32_t>(T)));
    for (const Voxel& v : cand.voxels()) bc.insert(spatialHash(v, static_cast<std::uint32_t>(T)));
    std::size_t xr = 0, nw = 0;
    for (std::uint32_t b = 0; b < T; ++b) {
      xr += bo.count(b) != bc.count(b);
      nw += bc.count(b) && !bo.count(b);
    }
    const HashedBits ho = HashedBits::encode(obs, T), hc = HashedBits::encode(cand, T);
    EXPECT_EQ(ho.count(), bo.size());
    const CoverageScore s = scoreHashed(ho, hc);
    EXPECT_EQ(s.differing, xr);
    EXPECT_EQ(s.new_count, nw);
    EXPECT_DOUBLE_EQ(s.hamming, static_cast<double>(xr) / T);
    EXPECT_LE(s.hamming, 1.0);
  }
}

TEST(HashCollisions, OccupiedBucketsMatchTheRandomHashTheory) {
  // Measured occupied buckets of random voxel sets vs T (1 - (1 - 1/T)^n), within 5
  // standard deviations, for load factors from 0.05 to 4.
  std::mt19937_64 rng(23);
  std::printf("[ hash collisions, random voxels ]\n      T        n   occupied   expected   sigma  colliding%%\n");
  for (int log2T : {11, 13, 15, 17, 19}) {
    const double T = std::ldexp(1.0, log2T);
    for (double load : {0.05, 0.5, 4.0}) {
      const auto n = static_cast<std::size_t>(load * T);
      if (n > 200000) continue;
      const VoxelSet s = randomVoxelSet(rng, n);
      const double measured = static_cast<double>(HashedBits::encode(s, static_cast<std::size_t>(T)).count());
      const double e = expectedOccupied(static_cast<double>(n), T);
      const double sd = std::sqrt(varianceOccupied(static_cast<double>(n), T));
      std::printf("%7.0f %8zu %10.0f %10.1f %7.2f %10.3f\n", T, n, measured, e, sd, 100.0 * (1 - measured / n));
      EXPECT_LE(std::abs(measured - e), 5 * sd + 1) << "T=" << T << " n=" << n;
    }
  }
}

TEST(HashCollisions, Room360ScoresDeviateFromExactAsTheoryPredicts) {
  // On a real scene grid (structured, spatially coherent voxels) the error of the hashed
  // scores vs the exact ones is compared with the random-hash prediction computed from
  // the exact set sizes.
  const auto& sc = test::room360Sfm();
  OccupancyOptions o;
  o.resolution = 96;
  o.upsample = 2;
  o.trim_percent = 0.5;
  OccupancyGrids g = OccupancyGrids::fromSfm(sc.points, o);
  // Observed: SfM-like points of four train views' surfaces, i.e. depth-map points.
  std::vector<Eigen::Vector3d> sa;
  for (int k = 0; k < 4; ++k) {
    const Camera& cam = sc.scene.cameras[sc.scene.train[k * 7]];
    const ImageF depth = sc.scene.renderDepth(cam);
    for (int v = 0; v < depth.height; v += 3)
      for (int u = 0; u < depth.width; u += 3)
        if (depth.at(u, v) > 0) sa.push_back(cam.unproject(Eigen::Vector2d(u + 0.5, v + 0.5), depth.at(u, v)));
  }
  g.addObserved(sa);
  const VoxelSet obs = g.observedSceneVoxels();
  ASSERT_GT(obs.size(), 1000u);
  std::printf("[ hashed vs exact, room360: %zu scene voxels, %zu observed ]\n", g.sceneCount(), obs.size());
  std::printf("  log2T  cand  xor exact  xor hashed  xor expected  new exact  new hashed  new expected\n");
  for (int log2T : {11, 13, 15, 17, 19}) {
    const std::size_t T = std::size_t{1} << log2T;
    const HashedBits ho = HashedBits::encode(obs, T);
    double sum_err_xor = 0, sum_pred_xor = 0, sum_err_new = 0, sum_pred_new = 0;
    for (std::size_t j = 0; j < sc.scene.cameras.size(); j += 10) {
      const VoxelSet cand = frustumSet(g, sc.scene.cameras[j]);
      const CoverageScore ex = scoreExact(obs, cand, g.sceneCount());
      const CoverageScore hs = scoreHashed(ho, HashedBits::encode(cand, T));
      const double a = static_cast<double>(differenceSize(obs, cand));
      const double b = static_cast<double>(ex.new_count);
      const double c = static_cast<double>(intersectionSize(obs, cand));
      const double ex_xor = expectedXor(a, b, c, static_cast<double>(T));
      const double ex_new = expectedNew(a, b, c, static_cast<double>(T));
      // Hashing can only merge voxels: never more differing or new bits than voxels.
      EXPECT_LE(hs.differing, ex.differing);
      EXPECT_LE(hs.new_count, ex.new_count);
      sum_err_xor += static_cast<double>(ex.differing) - hs.differing;
      sum_pred_xor += static_cast<double>(ex.differing) - ex_xor;
      sum_err_new += static_cast<double>(ex.new_count) - hs.new_count;
      sum_pred_new += static_cast<double>(ex.new_count) - ex_new;
      if (j == 0)
        std::printf("  %5d  %4zu  %9zu  %10zu  %12.1f  %9zu  %10zu  %12.1f\n", log2T, j, ex.differing, hs.differing,
                    ex_xor, ex.new_count, hs.new_count, ex_new);
    }
    std::printf("  log2T %d: total xor loss measured %.0f, predicted %.0f; new loss measured %.0f, predicted %.0f\n",
                log2T, sum_err_xor, sum_pred_xor, sum_err_new, sum_pred_new);
    // Summed over the candidates, the collision loss is never much above the random-hash
    // prediction (the hash spreads scene voxels at least as well as a random function),
    // and where the prediction is large (loads >= ~0.1) it is within 25 % of it: a
    // wrong hash, a wrong table size or a wrong score lands far off. At low loads the
    // measured loss is below the prediction: spatially coherent voxels collide less than
    // random ones (x enters h(x) with factor 1, so a run of consecutive x fills
    // consecutive buckets), hence the one-sided bound there.
    for (const auto& [err, pred] : {std::pair{sum_err_xor, sum_pred_xor}, std::pair{sum_err_new, sum_pred_new}}) {
      EXPECT_LE(err, 1.25 * pred + 20) << "log2T " << log2T;
      if (pred >= 500) {
        EXPECT_GE(err, 0.75 * pred) << "log2T " << log2T;
      }
    }
  }
}

TEST(Prefilter, ScoreCandidatesHashedAndExact) {
  std::mt19937_64 rng(25);
  const VoxelSet obs = randomVoxelSet(rng, 2000);
  std::vector<VoxelSet> cands;
  for (int j = 0; j < 9; ++j) cands.push_back(randomVoxelSet(rng, 100 + 150 * j));
  cands.emplace_back();  // a candidate that sees nothing
  CoverageScoring o;
  o.encoding = CoverageEncoding::Exact;
  const auto ex = scoreCandidates(obs, cands, 50000, o);
  o.encoding = CoverageEncoding::Hashed;
  o.table_size = 1u << 19;
  const auto hs = scoreCandidates(obs, cands, 50000, o);
  ASSERT_EQ(ex.size(), cands.size());
  for (std::size_t j = 0; j < cands.size(); ++j) {
    EXPECT_EQ(ex[j].new_count, cands[j].size());  // disjoint random sets (w.h.p.)
    EXPECT_TRUE(std::isfinite(ex[j].hamming) && std::isfinite(hs[j].hamming));
    // At load ~0.01 a few collisions at most.
    EXPECT_NEAR(static_cast<double>(hs[j].new_count), static_cast<double>(ex[j].new_count), 0.02 * ex[j].new_count + 2);
  }
  // The batch scorer gives exactly the dense bit-vector scores.
  for (std::size_t T : {std::size_t{1} << 11, std::size_t{1} << 19}) {
    o.table_size = T;
    const auto batch = scoreCandidates(obs, cands, 50000, o);
    const HashedBits ho = HashedBits::encode(obs, T);
    for (std::size_t j = 0; j < cands.size(); ++j) {
      const CoverageScore d = scoreHashed(ho, HashedBits::encode(cands[j], T));
      EXPECT_EQ(batch[j].differing, d.differing);
      EXPECT_EQ(batch[j].new_count, d.new_count);
      EXPECT_EQ(batch[j].hamming, d.hamming);
    }
  }
  EXPECT_EQ(ex.back().new_count, 0u);
  EXPECT_EQ(ex.back().differing, obs.size());
  // Larger candidates add more: by either criterion and encoding, candidate j + 1
  // (150 voxels more) scores above candidate j, and the empty one scores lowest.
  for (const auto* scores : {&hs, &ex})
    for (CoverageCriterion c : {CoverageCriterion::NewCount, CoverageCriterion::Hamming}) {
      for (std::size_t j = 0; j + 2 < cands.size(); ++j)
        EXPECT_GT(criterionValue((*scores)[j + 1], c), criterionValue((*scores)[j], c)) << j;
      EXPECT_LT(criterionValue(scores->back(), c), criterionValue(scores->front(), c));
    }
  o.encoding = CoverageEncoding::Exact;
  EXPECT_TRUE(scoreCandidates(obs, {}, 50000, o).empty());
}

TEST(Prefilter, HammingAndNewCountRankDifferently) {
  // The XOR distance also rewards *not* seeing observed voxels; the new-voxel count does
  // not. E sees 990 observed voxels and 40 new ones, F sees only 20 new ones:
  // XOR(E) = 10 + 40 = 50, XOR(F) = 1000 + 20 = 1020, new(E) = 40, new(F) = 20.
  std::mt19937_64 rng(26);
  const VoxelSet obs = randomVoxelSet(rng, 1000);
  const std::vector<Voxel> ov = obs.voxels();
  std::vector<Voxel> fresh = randomVoxelSet(rng, 60).voxels();
  ASSERT_EQ(intersectionSize(obs, VoxelSet::fromVoxels(fresh)), 0u);
  std::vector<Voxel> e(ov.begin(), ov.begin() + 990);
  e.insert(e.end(), fresh.begin(), fresh.begin() + 40);
  const std::vector<Voxel> f(fresh.begin() + 40, fresh.end());
  const std::vector<VoxelSet> cands{VoxelSet::fromVoxels(e), VoxelSet::fromVoxels(f)};
  for (CoverageEncoding enc : {CoverageEncoding::Exact, CoverageEncoding::Hashed}) {
    CoverageScoring o;
    o.encoding = enc;
    const auto sc = scoreCandidates(obs, cands, 100000, o);
    EXPECT_GT(criterionValue(sc[1], CoverageCriterion::Hamming), criterionValue(sc[0], CoverageCriterion::Hamming));
    EXPECT_GT(criterionValue(sc[0], CoverageCriterion::NewCount), criterionValue(sc[1], CoverageCriterion::NewCount));
  }
}

namespace saresgs {
namespace {

// Voxels on the x axis hash to x mod T (the y and z products are 0), so the collisions of
// a hand-made set are known: {0, 1, 2, 3, 9} in T = 8 bits sets bits 0-3, and 9 shares
// bit 1 with voxel 1.
TEST(HashLoad, HandMadeSetGivesItsLoadBitsAndCollisions) {
  std::vector<Voxel> v;
  for (int x : {0, 1, 2, 3, 9}) v.push_back({x, 0, 0});
  const VoxelSet s = VoxelSet::fromVoxels(v);
  const HashLoad h = hashLoad(s, 8);
  EXPECT_EQ(h.voxels, 5u);
  EXPECT_EQ(h.table_size, 8u);
  EXPECT_EQ(h.bits_set, 4u);
  EXPECT_EQ(h.colliding, 1u);
  EXPECT_DOUBLE_EQ(h.load, 5.0 / 8.0);
  // Without 9 there is no collision; in 16 bits 9 has a bit of its own.
  EXPECT_EQ(hashLoad(VoxelSet::fromVoxels(std::vector<Voxel>(v.begin(), v.end() - 1)), 8).colliding, 0u);
  EXPECT_EQ(hashLoad(s, 16).colliding, 0u);
  EXPECT_EQ(hashLoad(VoxelSet{}, 8).load, 0.0);
}

TEST(HashLoad, TableSizeForALoadOfAtMostAHalf) {
  EXPECT_EQ(hashTableSizeFor(0), std::size_t{1} << 11);
  EXPECT_EQ(hashTableSizeFor(1024), std::size_t{1} << 11);  // exactly 0.5
  EXPECT_EQ(hashTableSizeFor(1025), std::size_t{1} << 12);
  EXPECT_EQ(hashTableSizeFor(24112), std::size_t{1} << 16);       // room360's scene voxels at grid 64, m = 2
  EXPECT_EQ(hashTableSizeFor(10'000'000), std::size_t{1} << 19);  // beyond the paper's range: its largest
  EXPECT_EQ(hashTableSizeFor(300, 0.1, 11, 19), std::size_t{1} << 12);
}

}  // namespace
}  // namespace saresgs
