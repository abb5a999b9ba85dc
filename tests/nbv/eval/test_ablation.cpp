// The ablation grid: config errors, job expansion and shards, the ranking-error measures
// against independent formulas, tables, and the prefilter sweep on a tiny synthetic scene.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <map>
#include <set>

#include "common/test_support.h"
#include "common/tiny_dataset.h"
#include "geometry/occupancy/coverage_score.h"
#include "geometry/occupancy/occupancy_grid.h"
#include "geometry/synth/from_manifest.h"
#include "nbv/prefilter_options.h"
#include "nbv/eval/ablation.h"
#include "nbv/active_run.h"
#include "nbv/eval/prefilter_sweep.h"

using namespace saresgs;
using saresgs::test::TempDir;
using saresgs::test::throwsInputError;
using saresgs::test::writeBytes;

namespace {

const char* kGrid = R"({
  "preset": "quick",
  "scenes": [{"name": "a", "dataset": "data/a"}, {"name": "b", "dataset": "data/b", "layout": "object"}],
  "methods": ["random", "sa-resgs"],
  "seeds": [0, 1],
  "method_args": {"sa-resgs": ["--time-exhaustive-fisher"]},
  "variants": [{"name": "default"}, {"name": "beta0.2", "methods": ["sa-resgs"], "args": ["--residual-beta", "0.2"]}],
  "sweep": {"scenes": ["b"], "views": [4]}
})";

}  // namespace

TEST(Ablation, GridExpandsIntoEveryCombinationOnce) {
  TempDir d;
  writeBytes(d.file("g.json"), kGrid);
  const AblationGrid g = readAblationGrid(d.file("g.json"));
  const std::vector<AblationJob> jobs = expandGrid(g);
  // 1 sweep + 2 scenes x (random: 1 variant + sa-resgs: 2 variants) x 2 seeds.
  ASSERT_EQ(jobs.size(), 1u + 2 * 3 * 2);
  EXPECT_EQ(jobs[0].kind, AblationJob::Kind::kSweep);
  std::set<std::string> ids;
  for (const auto& j : jobs) ids.insert(j.id);
  EXPECT_EQ(ids.size(), jobs.size());
  for (const auto& j : jobs) {
    if (j.kind != AblationJob::Kind::kActive) continue;
    const auto has = [&](const std::string& s) { return std::find(j.args.begin(), j.args.end(), s) != j.args.end(); };
    EXPECT_EQ(has("--time-exhaustive-fisher"), j.method == "sa-resgs") << j.id;
    EXPECT_EQ(has("--residual-beta"), j.variant == "beta0.2") << j.id;
    EXPECT_NE(j.method == "random", j.variant == "beta0.2" || j.method == "sa-resgs") << j.id;
  }
  // Shards partition the jobs.
  std::multiset<std::string> shard_ids;
  for (int i = 0; i < 3; ++i)
    for (const auto& j : shardJobs(jobs, i, 3)) shard_ids.insert(j.id);
  EXPECT_EQ(std::set<std::string>(shard_ids.begin(), shard_ids.end()), ids);
  EXPECT_EQ(shard_ids.size(), ids.size());
  EXPECT_EQ(parseShard("1/2"), std::make_pair(1, 2));
  EXPECT_THROW(parseShard("2/2"), std::invalid_argument);
  EXPECT_THROW(parseShard("1"), std::invalid_argument);
  EXPECT_THROW(parseShard("1/2x"), std::invalid_argument);
}

// A method may run on fewer seeds than the grid's (method_seeds, among "seeds"); the
// others keep the grid's seeds, and a seed outside "seeds" is refused by field.
// A scene's scene_seed is read as the generator's --seed (another capture of the type);
// without it, seed 0, the built-in captures.
TEST(Ablation, SceneSeedIsReadPerScene) {
  TempDir d;
  writeBytes(d.file("g.json"), R"({"scenes": [{"name": "a", "dataset": "x", "layout": "room360", "scene_seed": 7},
                                             {"name": "b", "dataset": "y", "layout": "object"}], "methods": ["random"]})");
  const AblationGrid g = readAblationGrid(d.file("g.json"));
  ASSERT_EQ(g.scenes.size(), 2u);
  EXPECT_EQ(g.scenes[0].scene_seed, 7u);
  EXPECT_EQ(g.scenes[1].scene_seed, 0u);
}

TEST(Ablation, MethodSeedsNarrowOneMethodsSeeds) {
  TempDir d;
  nlohmann::json j = {{"scenes", {{{"name", "a"}, {"dataset", "x"}}}},
                      {"methods", {"random", "fisher"}},
                      {"seeds", {0, 1, 2, 3}},
                      {"method_seeds", {{"fisher", {1, 3}}}}};
  writeBytes(d.file("g.json"), j.dump());
  std::vector<std::string> ids;
  for (const AblationJob& job : expandGrid(readAblationGrid(d.file("g.json")))) ids.push_back(job.id);
  EXPECT_EQ(ids,
            (std::vector<std::string>{"a__random__default__s0", "a__random__default__s1", "a__random__default__s2",
                                      "a__random__default__s3", "a__fisher__default__s1", "a__fisher__default__s3"}));
  j["method_seeds"]["fisher"] = {1, 7};
  writeBytes(d.file("g.json"), j.dump());
  EXPECT_TRUE(throwsInputError([&] { readAblationGrid(d.file("g.json")); }, d.file("g.json"), "method_seeds.fisher"));
  j["method_seeds"] = {{"clairvoyant", {1}}};
  writeBytes(d.file("g.json"), j.dump());
  EXPECT_TRUE(throwsInputError([&] { readAblationGrid(d.file("g.json")); }, d.file("g.json"), "method_seeds"));
}

TEST(Ablation, GridTakesEveryMethodOfTheList) {
  TempDir d;
  nlohmann::json j = {{"scenes", {{{"name", "a"}, {"dataset", "x"}}}}, {"methods", methodNames()}};
  writeBytes(d.file("g.json"), j.dump());
  const AblationGrid g = readAblationGrid(d.file("g.json"));
  EXPECT_EQ(g.methods, methodNames());
  EXPECT_EQ(expandGrid(g).size(), allMethods().size());
}

TEST(Ablation, MalformedGridsNameTheFileAndField) {
  TempDir d;
  const std::string f = d.file("g.json");
  auto bad = [&](const std::string& text, const std::string& field) {
    writeBytes(f, text);
    return throwsInputError([&] { readAblationGrid(f); }, f, field);
  };
  EXPECT_TRUE(bad("{", "json"));
  EXPECT_TRUE(bad(R"({"scenes": []})", "scenes"));
  EXPECT_TRUE(bad(R"({"scenes": [{"name": "a", "dataset": "x"}], "methods": ["nope"]})", "methods"));
  // Sweep options are checked when the grid is read, not when its job runs.
  EXPECT_TRUE(bad(R"({"scenes": [{"name": "a", "dataset": "x"}], "sweep": {"sets": ["frustrum"]}})", "sweep.sets"));
  EXPECT_TRUE(
      bad(R"({"scenes": [{"name": "a", "dataset": "x"}], "sweep": {"encodings": ["hash:31"]}})", "sweep.encodings"));
  EXPECT_TRUE(bad(R"({"scenes": [{"name": "a", "dataset": "x"}], "sweep": {"scores": ["and"]}})", "sweep.scores"));
  EXPECT_TRUE(bad(R"({"scenes": [{"name": "a", "dataset": "x"}], "sweep": {"lifting": "sift"}})", "sweep.lifting"));
  EXPECT_TRUE(bad(R"({"scenes": [{"name": "a", "dataset": "x"}], "methods": ["random"], "colour": 1})", "colour"));
  EXPECT_TRUE(bad(R"({"scenes": [{"name": "a/b", "dataset": "x"}], "methods": ["random"]})", "scenes[0].name"));
  EXPECT_TRUE(
      bad(R"({"scenes": [{"name": "a", "dataset": "x"}, {"name": "a", "dataset": "y"}], "methods": ["random"]})",
          "scenes[1].name"));
  EXPECT_TRUE(bad(R"({"scenes": [{"name": "a", "dataset": "x"}], "methods": ["random"], "seeds": "0"})", "seeds"));
  EXPECT_TRUE(bad(R"({"scenes": [{"name": "a", "dataset": "x"}], "sweep": {"scenes": ["z"]}})", "sweep.scenes"));
  EXPECT_TRUE(bad(R"({"scenes": [{"name": "a", "dataset": "x"}]})", "methods"));
  // Values are checked as read: a negative or fractional seed no longer wraps or truncates,
  // threads are a count, repeats are refused, and the messages are ours.
  const std::string scene = R"({"scenes": [{"name": "a", "dataset": "x"}], "methods": ["random"], )";
  for (
      const auto& [text, field] : std::vector<std::pair<std::string, std::string>>{
          {scene + R"("seeds": [0, -1]})", "seeds[1]: expected a whole number in 0.."},
          {scene + R"("seeds": [0.5]})", "seeds[0]: expected a whole number"},
          {scene + R"("seeds": ["1"]})", "seeds[0]: expected a whole number"},
          {scene + R"("seeds": [1, 2, 1]})", "seeds[2]: 1 appears twice"},
          {scene + R"("threads": -2})", "threads: expected a whole number in 0..1024"},
          {scene + R"("threads": "two"})", "threads: expected a whole number"},
          {scene + R"("threads": 1e12})", "threads"},
          {scene + R"("preset": 3})", "preset"},
          {R"({"scenes": [{"name": "a", "dataset": "x"}], "methods": ["random", "fvs", "random"]})",
           "methods[2]: random appears twice"},
          {scene + R"("sweep": {"views": [4, -1]}})", "sweep.views[1]: expected a whole number in 1.."},
          {scene + R"("sweep": {"views": "4"}})", "sweep.views: expected an array"},
          {scene + R"("sweep": {"keep": 2}})", "sweep.keep: expected a number in 0..1"},
          {scene + R"("sweep": {"keep": 0}})", "sweep.keep"},
          {scene + R"("sweep": {"timing_repeats": 0}})", "sweep.timing_repeats"},
          {R"({"scenes": [{"name": "a", "dataset": "x", "layout": "object", "scene_seed": -1}], "methods": ["random"]})",
           "scenes[0].scene_seed: expected a non-negative integer"},
          {R"({"scenes": [{"name": "a", "dataset": "x", "scene_seed": 1}], "methods": ["random"]})",
           "scenes[0].scene_seed: given without a layout"},
          {R"({"scenes": [{"name": "a", "dataset": "x", "layuot": "object"}], "methods": ["random"]})",
           "scenes[0].\"layuot\": unknown field"},
      }) {
    writeBytes(f, text);
    std::string msg;
    try {
      readAblationGrid(f);
    } catch (const InputError& e) {
      msg = e.what();
    }
    EXPECT_NE(msg.find(f + ": " + field), std::string::npos) << text << ": " << msg;
    EXPECT_EQ(msg.find("json.exception"), std::string::npos) << msg;
  }
}

// tau-b from its textbook definition: sum of sign products over pairs, normalised by the
// untied pair counts of each ranking.
static double tauOracle(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0, n1 = 0, n2 = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = i + 1; j < a.size(); ++j) {
      const double sa = (a[i] > a[j]) - (a[i] < a[j]), sb = (b[i] > b[j]) - (b[i] < b[j]);
      s += sa * sb;
      n1 += sa != 0;
      n2 += sb != 0;
    }
  return s / std::sqrt(n1 * n2);
}

TEST(Ablation, KendallTauMatchesItsDefinitionWithTies) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> small(0, 4);  // many ties
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<double> a(30), b(30);
    for (std::size_t i = 0; i < a.size(); ++i) {
      a[i] = small(rng);
      b[i] = a[i] + small(rng) - 2;
    }
    EXPECT_NEAR(kendallTauB(a, b), tauOracle(a, b), 1e-12);
  }
  const std::vector<double> up{1, 2, 3, 4}, down{4, 3, 2, 1}, flat{1, 1, 1, 1};
  EXPECT_DOUBLE_EQ(kendallTauB(up, up), 1.0);
  EXPECT_DOUBLE_EQ(kendallTauB(up, down), -1.0);
  EXPECT_DOUBLE_EQ(kendallTauB(flat, up), 0.0);  // a constant ranking carries no order
  EXPECT_THROW(kendallTauB(up, {1.0}), std::invalid_argument);
  // Top 50 % of 4 = 2 items: {3, 2} vs {3, 1}: one in common.
  EXPECT_DOUBLE_EQ(topOverlap({0, 5, 4, 9}, {0, 5, 4, 9}, 0.5), 1.0);
  EXPECT_DOUBLE_EQ(topOverlap({0, 1, 8, 9}, {0, 8, 1, 9}, 0.5), 0.5);
}

TEST(Ablation, TablesAggregateSeedsAndSplitMeanStdInCsv) {
  TempDir d;
  writeBytes(d.file("g.json"), kGrid);
  const AblationGrid g = readAblationGrid(d.file("g.json"));
  std::vector<JobResult> results;
  for (const AblationJob& j : expandGrid(g)) {
    if (j.kind != AblationJob::Kind::kActive || j.scene != "a" || j.method != "random") continue;
    RunReport r;
    r.psnr = j.seed == 0 ? 20.0 : 22.0;
    r.ssim = 0.5;
    r.iterations = 100;
    r.seconds.training = 2.0;
    r.end_to_end_seconds = 3.0;
    StepReport s4, s5;
    s4.views_before = 4;
    s4.progress_psnr = 15.0;
    s5.views_before = 5;
    s5.progress_psnr = 17.0;
    r.steps = {s4, s5};
    results.push_back({j, r, {}});
  }
  ASSERT_EQ(results.size(), 2u);
  const std::vector<Table> tables = ablationTables(g, results);
  const auto find = [&](const std::string& n) {
    for (const auto& t : tables)
      if (t.name == n) return t;
    ADD_FAILURE() << "no table " << n;
    return Table{};
  };
  const Table main = find("results");
  ASSERT_EQ(main.rows.size(), 1u);
  EXPECT_EQ(main.rows[0][3], "21.00 \u00b1 1.41");  // mean 21, sample std sqrt(2)
  EXPECT_EQ(main.rows[0][5], "n/a");                // no AUSE
  const std::string csv = main.csv();
  EXPECT_NE(csv.find("PSNR_mean,PSNR_std"), std::string::npos) << csv;
  EXPECT_NE(csv.find("21.00,1.41"), std::string::npos) << csv;
  const Table time = find("time");
  ASSERT_EQ(time.rows.size(), 1u);
  EXPECT_EQ(time.rows[0][10], "20.0");  // 2 s / 100 iterations
  const Table views = find("psnr_vs_views");
  ASSERT_EQ(views.rows.size(), 1u);
  EXPECT_EQ(views.rows[0][2], "15.00");
  EXPECT_EQ(views.rows[0][3], "17.00");
  EXPECT_FALSE(ablationPlots(g, results).empty());
}

TEST(Ablation, FinalFitPerViewTableAveragesEachTestViewOverSeeds) {
  TempDir d;
  writeBytes(d.file("g.json"), kGrid);
  const AblationGrid g = readAblationGrid(d.file("g.json"));
  std::vector<JobResult> results;
  for (const AblationJob& j : expandGrid(g)) {
    if (j.kind != AblationJob::Kind::kActive || j.scene != "a" || j.variant != "default") continue;
    RunReport r;
    FinalFitReport f;
    // random: views (20, 30) at seed 0 and (22, 31) at seed 1; sa-resgs has no final fit
    // at seed 1, so its cells are seed 0's alone and n says so.
    if (j.method == "random")
      f.views = {{"v0", j.seed == 0 ? 20.0 : 22.0, 0.5}, {"v1", j.seed == 0 ? 30.0 : 31.0, 0.5}};
    else if (j.seed == 0)
      f.views = {{"v0", 25.0, 0.5}, {"v1", 26.5, 0.5}};
    if (!f.views.empty()) r.final_fit = f;
    results.push_back({j, r, {}});
  }
  const Table t = finalFitPerViewTable(g, results);
  EXPECT_EQ(t.header, (std::vector<std::string>{"scene", "method", "n", "0", "1"}));
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[0], (std::vector<std::string>{"a", "random", "2", "21.00", "30.50"}));
  EXPECT_EQ(t.rows[1], (std::vector<std::string>{"a", "sa-resgs", "1", "25.00", "26.50"}));
  const std::vector<NamedPlot> plots = ablationPlots(g, results);
  EXPECT_TRUE(
      std::any_of(plots.begin(), plots.end(), [](const NamedPlot& p) { return p.name == "final_fit_per_view"; }));
}

// Against the better baseline: fisher ahead of fvs on scene a, fvs ahead on scene b; each
// other method paired with that one by seed (hand-computed means and t intervals).
TEST(Ablation, BetterBaselineIsChosenPerSceneAndPairedBySeed) {
  TempDir d;
  writeBytes(d.file("g.json"), R"({
    "preset": "quick",
    "scenes": [{"name": "a", "dataset": "data/a"}, {"name": "b", "dataset": "data/b"}],
    "methods": ["fvs", "fisher", "adaptive"],
    "seeds": [0, 1, 2]
  })");
  const AblationGrid g = readAblationGrid(d.file("g.json"));
  // Final-fit PSNR per (scene, method) and seed; adaptive on b has no seed 2.
  const std::map<std::pair<std::string, std::string>, std::vector<double>> psnr = {
      {{"a", "fisher"}, {30.0, 31.0, 32.0}},   {{"a", "fvs"}, {29.0, 30.5, 31.0}},
      {{"a", "adaptive"}, {30.5, 31.2, 32.9}}, {{"b", "fisher"}, {20.0, 20.0, 20.0}},
      {{"b", "fvs"}, {21.0, 20.5, 21.5}},      {{"b", "adaptive"}, {22.0, 21.5}}};
  std::vector<JobResult> results;
  for (const AblationJob& j : expandGrid(g)) {
    const std::vector<double>& v = psnr.at({j.scene, j.method});
    if (j.seed >= v.size()) continue;
    RunReport r;
    FinalFitReport f;
    f.psnr = v[j.seed];
    r.final_fit = f;
    results.push_back({j, r, {}});
  }
  const std::vector<BetterBaselineDifference> rows = againstBetterBaseline(g, results);
  ASSERT_EQ(rows.size(), 4u);
  auto row = [&](const std::string& scene, const std::string& method) {
    for (const auto& r : rows)
      if (r.scene == scene && r.method == method) return r;
    ADD_FAILURE() << "no row " << scene << " " << method;
    return BetterBaselineDifference{};
  };
  // a: fisher - fvs = 1, 0.5, 1, so fisher; adaptive - fisher = 0.5, 0.2, 0.9: mean 0.5333,
  // sd 0.35119, t(2) 4.3027, half width 0.8724.
  const auto aa = row("a", "adaptive");
  EXPECT_EQ(aa.baseline, "fisher");
  EXPECT_EQ(aa.d.n, 3);
  EXPECT_NEAR(aa.d.mean, 0.53333, 1e-4);
  ASSERT_TRUE(aa.d.ci_low && aa.d.ci_high);
  EXPECT_NEAR(*aa.d.ci_low, 0.53333 - 0.8724, 1e-3);
  EXPECT_NEAR(*aa.d.ci_high, 0.53333 + 0.8724, 1e-3);
  EXPECT_NEAR(row("a", "fvs").d.mean, -0.83333, 1e-4);
  // b: fisher - fvs = -1, -0.5, -1.5, so fvs; adaptive - fvs over seeds 0 and 1 only.
  const auto ba = row("b", "adaptive");
  EXPECT_EQ(ba.baseline, "fvs");
  EXPECT_EQ(ba.d.n, 2);
  EXPECT_NEAR(ba.d.mean, 1.0, 1e-9);
  EXPECT_NEAR(row("b", "fisher").d.mean, -1.0, 1e-9);
  // The table says which side of the baseline each method is, and whether its interval
  // excludes 0 (b's fisher: -1, -0.5, -1.5, sd 0.5, half width 1.242: it does not).
  const Table t = betterBaselineTable(g, results);
  ASSERT_EQ(t.rows.size(), 4u);
  for (const auto& r : t.rows) {
    if (r[0] == "b" && r[2] == "adaptive") {
      EXPECT_EQ(r[7], "at or above, interval clear of 0");
    }
    if (r[0] == "b" && r[2] == "fisher") {
      EXPECT_EQ(r[7], "below");
    }
  }
  const std::vector<NamedPlot> plots = ablationPlots(g, results);
  EXPECT_TRUE(std::any_of(plots.begin(), plots.end(), [](const NamedPlot& p) {
    return p.name == "final_fit_vs_better_baseline" && p.image.width > 100;
  }));
  // Without fvs in the grid there is no such comparison.
  writeBytes(d.file("g2.json"), R"({"preset": "quick", "scenes": [{"name": "a", "dataset": "data/a"}],
                                     "methods": ["fisher", "adaptive"], "seeds": [0]})");
  EXPECT_TRUE(againstBetterBaseline(readAblationGrid(d.file("g2.json")), results).empty());
}

TEST(Ablation, PrefilterSweepReferenceIsExactAndACollisionFreeHashMatchesIt) {
  const Scene& scene = test::tinyDataset();
  const auto truth = rebuildSyntheticScene(scene.source, scene);
  ASSERT_TRUE(truth);
  SweepSpec spec;
  spec.view_counts = {4, 6};
  spec.encodings.clear();
  for (const char* e : {"hash:2", "hash:20", "exact"}) {
    CoverageScoring c;
    parseCoverageEncoding(e, c, kSweepMinHashBits, kSweepMaxHashBits);
    spec.encodings.push_back(c);
  }
  spec.lifting = LiftingSource::kDepth;
  spec.timing_repeats = 1;
  PrefilterRegime regime;
  const auto rows = prefilterSweep(
      scene, spec, [&](const Camera& c) { return truth->render(c); },
      [&](const Camera& c) { return truth->renderDepth(c); }, 0, PrefilterConfig{}, &regime);
  ASSERT_EQ(rows.size(), 2u * 2 * 2 * 3);  // views x scores x sets x encodings
  // Are the scene voxels collision-free in a 2^20 table? Then hashed scores order the
  // candidates exactly as the exact ones do.
  auto pf = makeCoveragePrefilter(scene, PrefilterConfig{});
  std::set<std::uint32_t> bits;
  for (const Voxel& v : pf->grids().sceneVoxels().voxels()) bits.insert(spatialHash(v, 1u << 20));
  const bool collision_free = bits.size() == pf->grids().sceneCount();
  for (const SweepRow& r : rows) {
    EXPECT_TRUE(std::isfinite(r.kendall_tau) && std::isfinite(r.overlap)) << r.set << r.encoding;
    EXPECT_GT(r.candidates, 0);
    if (r.set == "visible" && r.encoding == "exact") {
      EXPECT_DOUBLE_EQ(r.kendall_tau, 1.0);
      EXPECT_DOUBLE_EQ(r.overlap, 1.0);
    }
    if (r.set == "visible" && r.encoding == "hash:20" && collision_free) {
      EXPECT_DOUBLE_EQ(r.kendall_tau, 1.0) << r.score;
    }
    if (r.encoding == "hash:2") {
      EXPECT_LT(r.kendall_tau, 0.999) << r.set << " " << r.score;  // 4 bits: nearly all collide
    }
  }
  EXPECT_TRUE(collision_free) << "pick a larger table for the test";
  // The grid swept is reported, and each hash's load is its scene voxels over its size.
  EXPECT_EQ(regime.scene_voxels, pf->grids().sceneCount());
  EXPECT_EQ(regime.min_points, PrefilterConfig{}.min_points);
  for (const SweepRow& r : rows) {
    const double expected = r.encoding == "hash:2"    ? regime.scene_voxels / 4.0
                            : r.encoding == "hash:20" ? regime.scene_voxels / double(1u << 20)
                                                      : 0.0;
    EXPECT_DOUBLE_EQ(r.load, expected) << r.encoding;
  }
  // An indoor grid (the paper's m = 5, resolution 32) is the one swept when given.
  PrefilterConfig indoor;
  applySceneType(indoor, SceneType::kIndoor);
  spec.view_counts = {4};
  spec.encodings.resize(1);
  PrefilterRegime indoor_regime;
  prefilterSweep(
      scene, spec, [&](const Camera& c) { return truth->render(c); },
      [&](const Camera& c) { return truth->renderDepth(c); }, 0, indoor, &indoor_regime);
  EXPECT_EQ(indoor_regime.min_points, 5);
  EXPECT_EQ(indoor_regime.resolution, 32);
  EXPECT_EQ(indoor_regime.scene_voxels, makeCoveragePrefilter(scene, indoor)->grids().sceneCount());
}

// Found with the ablation-config fuzz target (fuzz/fuzz_ablation_config.cpp): numbers of
// 1e30 where a whole number belongs were converted to int or uint64 (undefined
// behaviour); they are refused by field, as is a negative seed.
TEST(AblationGrid, NumbersOutOfRangeAreRefusedByField) {
  for (const auto& [input, field] :
       std::vector<std::pair<std::string, std::string>>{{"threads_1e30.json", "threads"},
                                                        {"seed_1e30.json", "seeds[0]"},
                                                        {"sweep_views_1e30.json", "sweep.views[0]"}}) {
    const std::string p = test::fuzzRegression("nbv/eval/fuzz_regressions/ablation_config/" + input);
    EXPECT_TRUE(throwsInputError([&] { readAblationGrid(p); }, p, field)) << input;
  }
  TempDir d;
  writeBytes(d.file("g.json"), R"({"scenes": [{"name": "a", "dataset": "x"}], "methods": ["random"], "seeds": [-1]})");
  EXPECT_TRUE(throwsInputError([&] { readAblationGrid(d.file("g.json")); }, d.file("g.json"), "seeds[0]"));
}

// Found by a 1M-input run of the ablation-config fuzz target: a key that is the empty
// string was reported as an unknown field with an empty name. Unknown keys are quoted.
TEST(AblationGrid, AnUnknownKeyIsNamedEvenWhenEmpty) {
  const std::string p = test::fuzzRegression("nbv/eval/fuzz_regressions/ablation_config/empty_key.json");
  EXPECT_TRUE(throwsInputError([&] { readAblationGrid(p); }, p, "\"\": unknown field"));
  TempDir d;
  writeBytes(d.file("g.json"), R"({"scenes": [{"name": "a", "dataset": "x"}], "methods": ["random"], "seedz": [1]})");
  EXPECT_TRUE(
      throwsInputError([&] { readAblationGrid(d.file("g.json")); }, d.file("g.json"), "\"seedz\": unknown field"));
}
