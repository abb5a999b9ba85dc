// The prefilter's typed configuration (parsed once from text) and its top-N cut.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "common/tiny_dataset.h"
#include "geometry/occupancy/occupancy_grid.h"
#include "nbv/prefilter_options.h"
#include "nbv/coverage_prefilter.h"

namespace saresgs {
namespace {

TEST(CoveragePrefilter, TextualOptionsParseAndNameRoundTrip) {
  for (CandidateSetKind k : {CandidateSetKind::kFrustum, CandidateSetKind::kVisible})
    EXPECT_EQ(parseCandidateSet(toString(k)), k);
  for (LiftingSource l : {LiftingSource::kFlow, LiftingSource::kDepth, LiftingSource::kOracle})
    EXPECT_EQ(parseLiftingSource(toString(l)), l);
  for (CoverageCriterion c : {CoverageCriterion::Hamming, CoverageCriterion::NewCount})
    EXPECT_EQ(parseCoverageCriterion(toString(c)), c);
  for (int bits = 11; bits <= 19; ++bits) {
    CoverageScoring s;
    s.criterion = CoverageCriterion::NewCount;
    parseCoverageEncoding("hash:" + std::to_string(bits), s);
    EXPECT_EQ(s.encoding, CoverageEncoding::Hashed);
    EXPECT_EQ(s.table_size, std::size_t{1} << bits);
    EXPECT_EQ(s.criterion, CoverageCriterion::NewCount);  // left alone
    EXPECT_EQ(encodingName(s), "hash:" + std::to_string(bits));
  }
  CoverageScoring s;
  parseCoverageEncoding("exact", s);
  EXPECT_EQ(s.encoding, CoverageEncoding::Exact);
  EXPECT_EQ(encodingName(s), "exact");
  parseCoverageEncoding("hash:auto", s);
  EXPECT_EQ(s.encoding, CoverageEncoding::Hashed);
  EXPECT_EQ(s.table_size, 0u);
  EXPECT_EQ(encodingName(s), "hash:auto");
  // The default configuration is the paper's: frustum sets, a hash sized for a load of at
  // most 0.5 in 2^11..2^19, XOR, 20 %, flow.
  const PrefilterConfig d;
  EXPECT_EQ(toString(d.set), std::string("frustum"));
  EXPECT_EQ(encodingName(d.scoring), "hash:auto");
  EXPECT_EQ(toString(d.scoring.criterion), std::string("xor"));
  EXPECT_EQ(d.keep_fraction, 0.2);
  EXPECT_EQ(d.lifting, LiftingSource::kFlow);
}

TEST(CoveragePrefilter, BadOptionsNameTheValue) {
  auto message = [](auto&& f) {
    try {
      f();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CoverageScoring s;
  EXPECT_NE(message([&] { parseCandidateSet("frustrum"); }).find("'frustrum'"), std::string::npos);
  EXPECT_NE(message([&] { parseLiftingSource("sift"); }).find("flow, depth or oracle"), std::string::npos);
  EXPECT_NE(message([&] { parseCoverageCriterion("and"); }).find("xor or new"), std::string::npos);
  for (const char* bad : {"hash:10", "hash:20", "hash:", "hash:13x", "hash:-3", "hash:999999999999", "exacto", ""})
    EXPECT_NE(message([&] { parseCoverageEncoding(bad, s); }).find("prefilter encoding"), std::string::npos) << bad;
  // The sweep's wider range.
  parseCoverageEncoding("hash:2", s, 2, 30);
  EXPECT_EQ(s.table_size, 4u);
}

// The paper's per-scene-type threshold (5 SfM points per voxel indoors, 2 outdoors), the
// built-in layouts' types, and the regime a built prefilter reports: its auto-sized hash
// holds the scene voxels at a load of at most 0.5, the bits it reports are those of the
// scene voxels' own encoding.
TEST(CoveragePrefilter, SceneTypesAndTheHashRegimeItReports) {
  PrefilterConfig c;
  applySceneType(c, parseSceneType("indoor"));
  EXPECT_EQ(c.min_points, 5);
  EXPECT_EQ(c.resolution, 32);
  applySceneType(c, SceneType::kOutdoor);
  EXPECT_EQ(c.min_points, 2);
  EXPECT_EQ(c.resolution, 64);
  EXPECT_THROW(parseSceneType("cave"), std::invalid_argument);
  EXPECT_EQ(sceneTypeOfLayout("room360"), SceneType::kIndoor);
  EXPECT_EQ(sceneTypeOfLayout("unbalanced"), SceneType::kIndoor);
  EXPECT_EQ(sceneTypeOfLayout("object"), SceneType::kOutdoor);
  EXPECT_FALSE(sceneTypeOfLayout("forest").has_value());

  const Scene& scene = test::tinyDataset();
  PrefilterConfig p;
  p.resolution = 24;
  const auto pre = makeCoveragePrefilter(scene, p);
  const PrefilterRegime r = pre->regime();
  ASSERT_TRUE(r.hash.has_value());
  EXPECT_EQ(r.scene_voxels, pre->grids().sceneCount());
  EXPECT_EQ(r.hash->voxels, r.scene_voxels);
  EXPECT_EQ(r.hash->table_size, hashTableSizeFor(r.scene_voxels));
  EXPECT_LE(r.hash->load, 0.5);
  EXPECT_EQ(r.hash->bits_set, HashedBits::encode(pre->grids().sceneVoxels(), r.hash->table_size).count());
  EXPECT_EQ(r.encoding, encodingName({CoverageEncoding::Hashed, CoverageCriterion::Hamming, r.hash->table_size}));
  const nlohmann::json j = toJson(r);
  EXPECT_EQ(j["load_factor"].get<double>(), r.hash->load);
  EXPECT_EQ(j["table_size"].get<std::size_t>(), r.hash->table_size);
  p.scoring.encoding = CoverageEncoding::Exact;
  const PrefilterRegime e = makeCoveragePrefilter(scene, p)->regime();
  EXPECT_EQ(e.encoding, "exact");
  EXPECT_FALSE(e.hash.has_value());
  EXPECT_FALSE(toJson(e).contains("load_factor"));
}

TEST(CoveragePrefilter, TopFractionCountsTiesAndNaN) {
  const std::vector<int> cand = {10, 4, 7, 2, 9};
  const std::vector<double> scores = {1, 3, 3, NAN, 0.5};
  EXPECT_EQ(topFraction(scores, cand, 0.2), std::vector<int>({4}));  // tie 4/7 -> lower view
  EXPECT_EQ(topFraction(scores, cand, 0.4), std::vector<int>({4, 7}));
  EXPECT_EQ(topFraction(scores, cand, 0.0), std::vector<int>({4}));               // at least one
  EXPECT_EQ(topFraction(scores, cand, 1.0), std::vector<int>({2, 4, 7, 9, 10}));  // NaN last but kept
  // k = max(1, ceil(M x fraction)), exact for the paper's 20 % of 150.
  for (const auto& [m, f, k] : {std::tuple{150, 0.2, 30}, {7, 0.2, 2}, {1, 0.2, 1}, {3, 0.01, 1}, {10, 1.0, 10}}) {
    std::vector<int> c(static_cast<std::size_t>(m));
    std::iota(c.begin(), c.end(), 0);
    EXPECT_EQ(topFraction(std::vector<double>(c.size(), 0.0), c, f).size(), static_cast<std::size_t>(k))
        << m << " " << f;
  }
  // Against a full stable sort on random scores with many ties (views in index order).
  std::mt19937_64 rng(24);
  std::uniform_int_distribution<int> d(0, 9);
  std::vector<double> r(200);
  for (double& x : r) x = d(rng);
  std::vector<int> idx(200);
  std::iota(idx.begin(), idx.end(), 0);
  std::vector<int> order = idx;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return r[a] > r[b]; });
  order.resize(40);
  std::sort(order.begin(), order.end());
  EXPECT_EQ(topFraction(r, idx, 0.2), order);
  EXPECT_THROW(topFraction({1.0}, {1, 2}, 0.2), std::invalid_argument);
}

}  // namespace
}  // namespace saresgs
