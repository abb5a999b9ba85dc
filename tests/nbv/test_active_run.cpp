// The active loop on a tiny synthetic scene: the protocol's view counts, a killed and
// resumed run equals an uninterrupted one bit for bit, and the coverage prefilter prefers
// the view of the unobserved side.
#include <algorithm>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <stdexcept>

#include "common/ring_run.h"
#include "common/test_support.h"
#include "common/tiny_active_options.h"
#include "common/tiny_dataset.h"
#include "geometry/error.h"
#include "nbv/prefilter_options.h"
#include "nbv/active_run.h"
#include "nbv/coverage_prefilter.h"
#include "nbv/selectors.h"

namespace saresgs {
namespace {

using test::TempDir;
using test::tinyDataset;

bool sameModel(const Gaussians& a, const Gaussians& b) {
  if (a.size() != b.size()) return false;
  return std::memcmp(a.means.data(), b.means.data(), a.means.size() * 4) == 0 &&
         std::memcmp(a.sh.data(), b.sh.data(), a.sh.size() * 4) == 0 &&
         std::memcmp(a.opacities.data(), b.opacities.data(), a.opacities.size() * 4) == 0;
}

TEST(ActiveRun, ProtocolCountsAndIterationBudget) {
  const Scene& s = tinyDataset();
  for (Method m : {Method::kRandom, Method::kFvs, Method::kFisher}) {
    ActiveRun run(s, tinyOptions(m));
    int last_iteration = 0, calls = 0;
    const ActiveResult r = run.run([&](const ActiveProgress& p) {
      EXPECT_GE(p.iteration, last_iteration);
      last_iteration = p.iteration;
      calls += p.phase == ActivePhase::kTraining;
    });
    ASSERT_EQ(r.initial_views.size(), 2u);
    EXPECT_EQ(r.initial_views[0], s.train[0]);
    ASSERT_EQ(r.selected_views.size(), 5u) << toString(m);
    std::set<int> distinct(r.selected_views.begin(), r.selected_views.end());
    EXPECT_EQ(distinct.size(), 5u);
    for (int v : r.selected_views) EXPECT_NE(std::find(s.train.begin(), s.train.end(), v), s.train.end());
    // 2*6 + 3*6 + 4*6 = 54 iterations over three selections, then the rest of 90.
    EXPECT_EQ(last_iteration, 90);
    EXPECT_EQ(calls, 90);  // one per training iteration
    EXPECT_EQ(r.iterations, 90);
    EXPECT_EQ(r.phase_iterations, (std::vector<int>{12, 18, 24, 36}));
    EXPECT_EQ(r.steps.size(), 4u);  // three selections and the final phase
    EXPECT_TRUE(std::isfinite(r.test.psnr));
    ASSERT_TRUE(r.ause.has_value());  // the synthetic dataset has depth
    EXPECT_TRUE(std::isfinite(*r.ause));
    if (m == Method::kFvs) {
      // Farthest view: the first selection maximises the distance to the initial views.
      const SelectionLog& l = r.steps[0];
      double best = -1;
      int best_view = -1;
      for (int c : l.candidates) {
        double d = 1e300;
        for (int v : r.initial_views) d = std::min(d, (s.views[c].camera.center() - s.views[v].camera.center()).norm());
        if (d > best) best = d, best_view = c;
      }
      EXPECT_EQ(l.selected, best_view);
    }
  }
}

TEST(ActiveRun, OnlyWhatAMethodNeedsIsComputed) {
  EXPECT_FALSE(needsOf(Method::kRandom).fisher);
  EXPECT_FALSE(needsOf(Method::kFvs).coverage);
  EXPECT_FALSE(needsOf(Method::kFisher).coverage);
  EXPECT_TRUE(needsOf(Method::kSaResgs).residual && needsOf(Method::kSaResgs).coverage);
  const Scene& s = tinyDataset();
  ActiveRun run(s, tinyOptions(Method::kRandom));
  const ActiveResult r = run.run();
  for (const auto& l : r.steps) {
    EXPECT_EQ(l.seconds.fisher, 0.0);
    EXPECT_EQ(l.seconds.lifting, 0.0);
    EXPECT_EQ(l.seconds.prefilter, 0.0);
  }
  EXPECT_THROW(parseMethod("clairvoyant"), std::invalid_argument);
}

// total_iterations is the loop's least total: when the phases' own k x interval add up to
// more, more runs, and the result says so (what `--min-iterations 300` means).
TEST(ActiveRun, TotalIterationsIsALeastTotalAndTheResultSaysWhatRan) {
  const Scene& s = tinyDataset();
  ActiveOptions o = tinyOptions(Method::kRandom);
  o.total_iterations = 40;
  const ActiveResult r = ActiveRun(s, o).run();
  EXPECT_EQ(r.phase_iterations, (std::vector<int>{12, 18, 24, 30}));  // the last: 5 views x 6
  EXPECT_EQ(r.iterations, 84);
}

TEST(ActiveRun, ResumedAfterAKillEqualsAnUninterruptedRun) {
  const Scene& s = tinyDataset();
  for (Method m : {Method::kFisher, Method::kSaResgs}) {
    TempDir d;
    ActiveRun whole(s, tinyOptions(m));
    const ActiveResult a = whole.run();
    struct Killed {};
    {
      ActiveRun first(s, tinyOptions(m), d.file("ckpt.json"));
      // Dies in the middle of the third phase, after two checkpoints.
      EXPECT_THROW(first.run([](const ActiveProgress& p) {
        if (p.iteration == 40) throw Killed{};
      }),
                   Killed);
    }
    ASSERT_TRUE(std::filesystem::exists(d.file("ckpt.json")));
    ActiveRun resumed(s, tinyOptions(m), d.file("ckpt.json"));
    const ActiveResult b = resumed.run();
    EXPECT_EQ(a.selected_views, b.selected_views) << toString(m);
    EXPECT_EQ(a.test.psnr, b.test.psnr) << toString(m);
    EXPECT_EQ(a.test.ssim, b.test.ssim);
    EXPECT_EQ(a.ause, b.ause);
    EXPECT_TRUE(sameModel(whole.trainer().gaussians(), resumed.trainer().gaussians())) << toString(m);
    ASSERT_EQ(a.steps.size(), b.steps.size());
    for (std::size_t k = 0; k < a.steps.size(); ++k) EXPECT_EQ(a.steps[k].scores, b.steps[k].scores);
  }
}

TEST(ActiveRun, CheckpointOfAnotherMethodIsRefused) {
  const Scene& s = tinyDataset();
  TempDir d;
  ActiveOptions o = tinyOptions(Method::kRandom);
  o.max_views = 3;
  ActiveRun(s, o, d.file("c.json")).run();
  ActiveRun other(s, tinyOptions(Method::kFvs), d.file("c.json"));
  EXPECT_TRUE(test::throwsInputError([&] { other.run(); }, d.file("c.json"), "method"));
}

// Every field of a checkpoint is checked against the run: a flipped or foreign value is
// an error naming the field, never a runaway phase or an index out of range.
TEST(ActiveRun, CorruptCheckpointFieldsAreRefusedByName) {
  const Scene& s = tinyDataset();
  TempDir d;
  const std::string ckpt = d.file("c.json");
  {
    ActiveRun first(s, tinyOptions(Method::kRandom), ckpt);
    struct Killed {};
    EXPECT_THROW(first.run([](const ActiveProgress& p) {
      if (p.iteration == 40) throw Killed{};
    }),
                 Killed);
  }
  const nlohmann::json good = nlohmann::json::parse(test::readBytes(ckpt));
  const auto refused = [&](const std::function<void(nlohmann::json&)>& corrupt, const std::string& field,
                           const ActiveOptions& o = tinyOptions(Method::kRandom)) {
    nlohmann::json j = good;
    corrupt(j);
    test::writeBytes(ckpt, j.dump());
    ActiveRun run(s, o, ckpt);
    return test::throwsInputError([&] { run.run(); }, ckpt, field);
  };
  EXPECT_TRUE(refused([](nlohmann::json& j) { j["iterations_done"] = -1e9; }, "iterations_done"));
  EXPECT_TRUE(refused([](nlohmann::json& j) { j["iterations_done"] = 1e30; }, "iterations_done"));
  EXPECT_TRUE(refused([](nlohmann::json& j) { j["iterations_done"] = j["iterations_done"].get<int>() + 1; },
                      "iterations_done"));
  EXPECT_TRUE(refused([](nlohmann::json& j) { j["selected"].back() = 100000; }, "selected"));
  EXPECT_TRUE(refused([](nlohmann::json& j) { j["selected"].back() = j["selected"][0]; }, "selected"));
  EXPECT_TRUE(refused([](nlohmann::json& j) { j["observed_upto"] = 99; }, "observed_upto"));
  EXPECT_TRUE(refused([](nlohmann::json& j) { j["steps"].erase(j["steps"].size() - 1); }, "steps"));
  EXPECT_TRUE(refused([](nlohmann::json& j) { j["initial"].erase(0); }, "initial"));
  ActiveOptions other_interval = tinyOptions(Method::kRandom);
  other_interval.interval = 7;
  EXPECT_TRUE(refused([](nlohmann::json&) {}, "iterations_done", other_interval));
  // Wrong JSON types name the field, never with nlohmann's or the standard library's
  // words ("type must be number", "vector::_M_range_check").
  const auto named = [&](const std::function<void(nlohmann::json&)>& corrupt, const std::string& field) {
    nlohmann::json j = good;
    corrupt(j);
    test::writeBytes(ckpt, j.dump());
    ActiveRun run(s, tinyOptions(Method::kRandom), ckpt);
    std::string msg;
    try {
      run.run();
    } catch (const InputError& e) {
      msg = e.what();
    }
    EXPECT_NE(msg.find(ckpt + ": " + field), std::string::npos) << field << ": " << msg;
    EXPECT_EQ(msg.find("json.exception"), std::string::npos) << msg;
    EXPECT_EQ(msg.find("_M_range_check"), std::string::npos) << msg;
  };
  named([](nlohmann::json& j) { j["initial"] = "0,1"; }, "initial: expected an array");
  named([](nlohmann::json& j) { j["selected"][1] = "x"; }, "selected[1]: expected a whole number");
  named([](nlohmann::json& j) { j["selected"][1] = -3; }, "selected[1]: expected a whole number in 0..");
  named([](nlohmann::json& j) { j["selected"][1] = 1e12; }, "selected[1]");
  named([](nlohmann::json& j) { j["iterations_done"] = "40"; }, "iterations_done: expected a whole number");
  named([](nlohmann::json& j) { j["seed"] = -1; }, "seed: expected a whole number");
  named([](nlohmann::json& j) { j["views"] = nullptr; }, "views: expected a whole number");
  named([](nlohmann::json& j) { j["rng"] = 5; }, "rng: expected a string");
  named([](nlohmann::json& j) { j["rng"] = "not a state"; }, "rng");
  named([](nlohmann::json& j) { j["tag"] = 3; }, "tag: expected a string");
  named([](nlohmann::json& j) { j["method"] = nlohmann::json::array(); }, "method: expected a string");
  named([](nlohmann::json& j) { j["steps"][0]["seconds"]["fisher"] = "slow"; },
        "steps[0].seconds.fisher: expected a number");
  named([](nlohmann::json& j) { j["steps"][0]["views_before"] = 2.5; },
        "steps[0].views_before: expected a whole number");
  named([](nlohmann::json& j) { j["steps"][0]["candidates"][0] = 7; }, "steps[0].candidates[0]: expected a string");
  named([](nlohmann::json& j) { j["steps"] = nlohmann::json::object(); }, "steps: expected an array");
  // The untouched checkpoint still resumes.
  test::writeBytes(ckpt, good.dump());
  ActiveRun ok(s, tinyOptions(Method::kRandom), ckpt);
  EXPECT_NO_THROW(ok.run());
}

// The prefilter's companion file holds raw points: a NaN among them is refused, naming
// the file.
TEST(ActiveRun, NonFinitePrefilterStateIsRefusedByFile) {
  const Scene& s = tinyDataset();
  TempDir d;
  const std::string ckpt = d.file("c.json");
  {
    ActiveRun first(s, tinyOptions(Method::kSaHash), ckpt);
    struct Killed {};
    EXPECT_THROW(first.run([](const ActiveProgress& p) {
      if (p.iteration == 40) throw Killed{};
    }),
                 Killed);
  }
  const nlohmann::json j = nlohmann::json::parse(test::readBytes(ckpt));
  const std::string companion = ckpt + ".prefilter." + j["tag"].get<std::string>();
  std::string bytes = test::readBytes(companion);
  ASSERT_GE(bytes.size(), sizeof(double));
  const double nan = std::nan("");
  std::memcpy(bytes.data(), &nan, sizeof nan);
  test::writeBytes(companion, bytes);
  ActiveRun resumed(s, tinyOptions(Method::kSaHash), ckpt);
  EXPECT_TRUE(test::throwsInputError([&] { resumed.run(); }, companion, "points"));
  test::writeBytes(companion, bytes.substr(0, bytes.size() - 1));
  ActiveRun truncated(s, tinyOptions(Method::kSaHash), ckpt);
  EXPECT_TRUE(test::throwsInputError([&] { truncated.run(); }, companion, "points"));
}

TEST(CoveragePrefilter, PrefersTheViewOfTheUnobservedSide) {
  const Scene& s = tinyDataset();
  const SyntheticScene truth = makeSyntheticScene(test::tinyDatasetOptions());
  const ViewRenderer render = [&](const Camera& c) { return truth.render(c); };
  const DepthRenderer depth = [&](const Camera& c) { return truth.renderDepth(c); };
  // Observe from the first train view; candidates: the train view nearest to it and the
  // one farthest from it (the other side of the object).
  const int seen = s.train[0];
  const Eigen::Vector3d c0 = s.views[seen].camera.center();
  int near = -1, far = -1;
  double dn = 1e300, df = -1;
  for (int v : s.train) {
    if (v == seen) continue;
    const double d = (s.views[v].camera.center() - c0).norm();
    if (d < dn) dn = d, near = v;
    if (d > df) df = d, far = v;
  }
  // Around an object every frustum holds every voxel; only the visible set (what rays
  // hit first) tells the sides apart.
  for (const char* lifting : {"depth", "flow"}) {
    for (const char* score : {"new", "xor"}) {
      for (const char* enc : {"exact", "hash:15"}) {
        PrefilterConfig pc;
        pc.set = CandidateSetKind::kVisible;
        pc.visible_stride = 1;
        pc.lifting = parseLiftingSource(lifting);
        pc.scoring.criterion = parseCoverageCriterion(score);
        parseCoverageEncoding(enc, pc.scoring);
        pc.resolution = 32;
        auto pf = makeCoveragePrefilter(s, pc);
        SelectionSeconds t;
        const auto before = pf->score({near, far}, t);
        pf->observe({seen}, render, depth, t);
        const auto sc = pf->score({near, far}, t);
        EXPECT_GT(sc[1], sc[0]) << lifting << " " << score << " " << enc;
        if (std::string(score) == "new") {
          // The observation covered some of what the near view sees, and more of it than
          // of what the far view sees.
          EXPECT_GT(before[0] - sc[0], before[1] - sc[1]) << lifting << " " << enc;
          EXPECT_GT(before[0] - sc[0], 0.0) << lifting << " " << enc;
        }
      }
    }
  }
  PrefilterConfig bad;
  EXPECT_THROW(parseCoverageEncoding("hash:40", bad.scoring), std::invalid_argument);
}

// The oracle source lifts from the dataset's own depth maps: the same SA-Points as the
// depth source fed the synthetic scene's true depth, without calling the caller's depth;
// a scene without depth maps is refused by name.
TEST(CoveragePrefilter, OracleLiftingUsesTheDatasetsGroundTruthDepth) {
  const Scene& s = tinyDataset();
  const SyntheticScene truth = makeSyntheticScene(test::tinyDatasetOptions());
  const ViewRenderer render = [&](const Camera& c) { return truth.render(c); };
  const DepthRenderer true_depth = [&](const Camera& c) { return truth.renderDepth(c); };
  const DepthRenderer unused = [](const Camera&) -> ImageF { throw std::logic_error("depth renderer called"); };
  ASSERT_TRUE(s.hasDepth(s.train[0]));
  PrefilterConfig pc;
  pc.resolution = 32;
  pc.lifting = LiftingSource::kDepth;
  auto by_depth = makeCoveragePrefilter(s, pc);
  pc.lifting = LiftingSource::kOracle;
  auto by_oracle = makeCoveragePrefilter(s, pc);
  SelectionSeconds t;
  by_depth->observe({s.train[0], s.train[1]}, render, true_depth, t);
  by_oracle->observe({s.train[0], s.train[1]}, render, unused, t);
  EXPECT_GT(by_oracle->liftingReport().kept, 0u);
  EXPECT_EQ(by_oracle->liftingReport().kept, by_depth->liftingReport().kept);
  EXPECT_EQ(by_oracle->save(), by_depth->save());

  Scene no_depth = s;
  for (auto& v : no_depth.views) v.depth_path.clear();
  try {
    makeCoveragePrefilter(no_depth, pc);
    ADD_FAILURE() << "a scene without depth maps was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("depth"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace saresgs

namespace saresgs {
namespace {

// The progress callback names every stage as it runs, with per-item counts, so that a
// front end can show a live line during selection as well as training.
TEST(ActiveRun, ProgressNamesEveryPhaseWithItsCounts) {
  const Scene& s = tinyDataset();
  ActiveOptions o = tinyOptions(Method::kSaResgs);
  o.time_exhaustive_fisher = true;
  ActiveRun run(s, o);
  std::map<ActivePhase, int> calls;
  std::map<ActivePhase, int> max_total;
  int last_iteration = 0;
  ActivePhase last_phase = ActivePhase::kTraining;
  run.run([&](const ActiveProgress& p) {
    ++calls[p.phase];
    max_total[p.phase] = std::max(max_total[p.phase], p.phase_total);
    EXPECT_GE(p.phase_done, 0);
    EXPECT_LE(p.phase_done, p.phase_total) << toString(p.phase);
    EXPECT_GE(p.iteration, last_iteration);
    last_iteration = p.iteration;
    last_phase = p.phase;
  });
  // 3 selections: training callbacks every iteration, lifting per new view (2 initial,
  // then 1 each), Fisher per prefiltered candidate plus a closing call.
  EXPECT_EQ(calls[ActivePhase::kTraining], 90);
  EXPECT_EQ(calls[ActivePhase::kLifting], 2 + 1 + 1);
  EXPECT_EQ(calls[ActivePhase::kPrefilter], 3);
  EXPECT_GE(calls[ActivePhase::kFisher], 3 * 2);
  EXPECT_GT(calls[ActivePhase::kExhaustiveFisher], calls[ActivePhase::kFisher]);
  EXPECT_EQ(calls[ActivePhase::kFinalEvaluation], 2);
  EXPECT_EQ(last_phase, ActivePhase::kFinalEvaluation);
  EXPECT_EQ(last_iteration, 90);
  for (ActivePhase p : {ActivePhase::kTraining, ActivePhase::kLifting, ActivePhase::kPrefilter, ActivePhase::kFisher,
                        ActivePhase::kExhaustiveFisher, ActivePhase::kFinalEvaluation})
    EXPECT_STRNE(toString(p), "?");
}

// Found with the active-checkpoint fuzz target (fuzz/fuzz_active_checkpoint.cpp): a view
// index of 1e30 in "selected", or a step's views_before of 1e30, was converted to int
// (undefined behaviour). The inputs are checkpoints of the fuzz fixture's run
// (fuzz/fuzz_fixtures.h: 6 views named view0.png .. view5.png, view 0 the test view,
// random selection from 2 views, seed 5); both are refused by field.
TEST(ActiveRun, CheckpointNumbersOutOfRangeAreRefusedByField) {
  Scene s = test::ringScene([](int i) { return "view" + std::to_string(i) + ".png"; }, true);
  ActiveOptions o = test::ringRunOptions();
  o.trainer.random_init_points = 8;
  for (const auto& [input, field] : std::vector<std::pair<std::string, std::string>>{
           {"selected_1e30.json", "selected"}, {"views_before_1e30.json", "steps[0].views_before"}}) {
    TempDir d;
    const std::string ckpt = d.file("checkpoint.json");
    test::writeBytes(ckpt, test::readBytes(test::fuzzRegression("nbv/fuzz_regressions/active_checkpoint/" + input)));
    ActiveRun run(s, o, ckpt);
    EXPECT_TRUE(test::throwsInputError([&] { run.run(); }, ckpt, field)) << input;
  }
}

}  // namespace
}  // namespace saresgs

namespace saresgs {
namespace {

// Fixed-order replay: a run of another method on a replayed sequence holds exactly that
// sequence, selects nothing (no Fisher pass, no prefilter) and refuses a sequence it could
// not have held.
TEST(ActiveRun, ReplayHoldsTheReplayedSequenceAndRefusesOnesItCouldNotHold) {
  const Scene& s = tinyDataset();
  const ActiveResult fisher = ActiveRun(s, tinyOptions(Method::kFisher)).run();
  ActiveOptions o = tinyOptions(Method::kSaResgs);
  o.replay = fisher.selected_views;
  const ActiveResult replay = ActiveRun(s, o).run();
  EXPECT_EQ(replay.selected_views, fisher.selected_views);
  EXPECT_EQ(replay.initial_views, fisher.initial_views);
  EXPECT_EQ(replay.total_seconds.selection(), 0.0);
  // A sequence in another order is held in that order (the initial views included).
  o.replay = fisher.selected_views;
  std::reverse(o.replay.begin(), o.replay.end());
  EXPECT_EQ(ActiveRun(s, o).run().selected_views, o.replay);
  // Too short, a repeated view, a view that is not a train view.
  o.replay.assign(fisher.selected_views.begin(), fisher.selected_views.begin() + 3);
  EXPECT_THROW(ActiveRun(s, o), std::invalid_argument);
  o.replay = fisher.selected_views;
  o.replay[4] = o.replay[1];
  EXPECT_THROW(ActiveRun(s, o), std::invalid_argument);
  o.replay = fisher.selected_views;
  ASSERT_FALSE(s.test.empty());
  o.replay[3] = s.test[0];
  EXPECT_THROW(ActiveRun(s, o), std::invalid_argument);
}

}  // namespace
}  // namespace saresgs

namespace saresgs {
namespace {

// The hybrid's ends are the selectors it mixes: at weight 0 it chooses what its Fisher
// criterion chooses (log-det: fisher-logdet; trace: fisher), at weight 1 with the view
// distance what farthest view sampling chooses; in between it logs both kinds of evidence.
TEST(ActiveRun, HybridAtItsEndsChoosesWhatTheSelectorsItMixesChoose) {
  const Scene& s = tinyDataset();
  auto views = [&](Method m, double w, FisherCriterion c, HybridCoverage k) {
    ActiveOptions o = tinyOptions(m);
    o.hybrid_weight = w;
    o.hybrid_criterion = c;
    o.hybrid_coverage = k;
    o.hybrid_surface.grid.resolution = 24;
    return ActiveRun(s, o).run();
  };
  const auto d = HybridCoverage::kViewDistance, sf = HybridCoverage::kSurface;
  const auto ld = FisherCriterion::kLogDet, tr = FisherCriterion::kTrace;
  EXPECT_EQ(views(Method::kHybrid, 0, ld, sf).selected_views, views(Method::kFisherLogDet, 0, ld, sf).selected_views);
  EXPECT_EQ(views(Method::kHybrid, 0, tr, d).selected_views, views(Method::kFisher, 0, ld, sf).selected_views);
  EXPECT_EQ(views(Method::kHybrid, 1, ld, d).selected_views, views(Method::kFvs, 0, ld, sf).selected_views);
  const ActiveResult mid = views(Method::kHybrid, 0.5, ld, sf);
  ASSERT_FALSE(mid.steps.empty());
  EXPECT_EQ(mid.steps[0].new_surface.size(), mid.steps[0].candidates.size());
  EXPECT_EQ(mid.steps[0].fisher_scores.size(), mid.steps[0].candidates.size());
  EXPECT_TRUE(mid.steps[0].view_distance.empty());
}

}  // namespace
}  // namespace saresgs

namespace saresgs {
namespace {

// The loop one piece at a time (what the Python module steps through) is run() itself:
// the same views, scores and model; a caller may hold a view of its own instead of the
// method's, and the calls refuse what the protocol does not allow.
TEST(ActiveRun, SteppingIsTheLoopAndTakesTheCallersViews) {
  const Scene& s = tinyDataset();
  ActiveRun whole(s, tinyOptions(Method::kFvs));
  const ActiveResult a = whole.run();
  ActiveRun stepped(s, tinyOptions(Method::kFvs));
  EXPECT_THROW(stepped.finish(), std::logic_error);  // 2 of 5 views held
  while (true) {
    stepped.trainPhase();
    if (stepped.finished()) break;
    SelectionLog log;
    const int v = stepped.nextView(&log);
    EXPECT_EQ(stepped.nextView(), v);  // computed once per phase
    EXPECT_EQ(log.scores.size(), log.candidates.size());
    stepped.addView(v);
  }
  EXPECT_THROW(stepped.nextView(), std::logic_error);
  const ActiveResult b = stepped.finish();
  EXPECT_EQ(a.selected_views, b.selected_views);
  EXPECT_EQ(a.test.psnr, b.test.psnr);
  EXPECT_TRUE(sameModel(whole.trainer().gaussians(), stepped.trainer().gaussians()));
  ASSERT_EQ(a.steps.size(), b.steps.size());
  for (std::size_t k = 0; k < a.steps.size(); ++k) EXPECT_EQ(a.steps[k].scores, b.steps[k].scores);

  ActiveRun mine(s, tinyOptions(Method::kFvs));
  const int proposed = mine.nextView();
  int other = -1;
  for (int v : s.train)
    if (v != proposed && std::find(mine.held().begin(), mine.held().end(), v) == mine.held().end()) other = v;
  mine.addView(other);
  EXPECT_EQ(mine.held().back(), other);
  EXPECT_THROW(mine.addView(other), std::invalid_argument);           // held already
  EXPECT_THROW(mine.addView(s.test.front()), std::invalid_argument);  // not a train view
}

// A caller's selector plugged into the loop: drawing from the run's generator as `random`
// does, it reproduces the built-in random run bit for bit; a choice that is not a
// candidate is refused by name; the CLI's method `custom` without a selector is refused.
TEST(ActiveRun, CustomSelectorPlugsIntoTheSameLoop) {
  const Scene& s = tinyDataset();
  ActiveRun builtin(s, tinyOptions(Method::kRandom));
  const ActiveResult a = builtin.run();
  ActiveOptions o = tinyOptions(Method::kCustom);
  int calls = 0;
  o.custom_selector = [&](const SelectionContext& c, SelectionLog&) {
    ++calls;
    EXPECT_GT(c.trainer.gaussians().size(), 0u);  // the model trained on the held views
    EXPECT_EQ(c.held.size() + c.candidates.size(), s.train.size());
    return selectRandom(c.candidates, c.rng);
  };
  ActiveRun custom(s, o);
  const ActiveResult b = custom.run();
  EXPECT_EQ(calls, 3);
  EXPECT_EQ(a.selected_views, b.selected_views);
  EXPECT_EQ(a.test.psnr, b.test.psnr);
  EXPECT_TRUE(sameModel(builtin.trainer().gaussians(), custom.trainer().gaussians()));

  o.custom_selector = [](const SelectionContext& c, SelectionLog&) { return c.held.front(); };
  ActiveRun wrong(s, o);
  try {
    wrong.run();
    ADD_FAILURE() << "a held view was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("not a candidate"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ActiveRun(s, tinyOptions(Method::kCustom)), std::invalid_argument);
}

}  // namespace
}  // namespace saresgs

namespace saresgs {
namespace {

// A gated selector is Fisher on its gate's top fraction: with the whole pool kept it is
// fisher, view for view; with a pool of one it is the gate's own selector (`alone`); in
// between every chosen view was in the logged pool, the pool is the top fraction by the
// gate's score, and Fisher ranked exactly the pool.
using GateScores =
    std::function<std::vector<double>(const Scene&, const std::vector<int>& held, const std::vector<int>& all)>;
void expectFisherOnTheGatesTopFraction(Method gated, Method alone, const GateScores& gate) {
  const Scene& s = tinyDataset();
  auto run = [&](Method m, double keep) {
    ActiveOptions o = tinyOptions(m);
    o.gate_keep = keep;
    return ActiveRun(s, o).run();
  };
  EXPECT_EQ(run(gated, 1).selected_views, run(Method::kFisher, 1).selected_views);
  EXPECT_EQ(run(gated, 1e-9).selected_views, run(alone, 1).selected_views);
  const ActiveResult r = run(gated, 0.3);
  ASSERT_FALSE(r.steps.empty());
  int selections = 0;
  for (const SelectionLog& st : r.steps) {
    if (st.selected < 0) continue;  // the last step logs training, no selection
    EXPECT_EQ(st.candidates, st.prefiltered);
    const std::vector<int> held(r.selected_views.begin(), r.selected_views.begin() + st.views_before);
    std::vector<int> all;
    for (int v : s.train)
      if (std::find(held.begin(), held.end(), v) == held.end()) all.push_back(v);
    EXPECT_EQ(st.prefiltered, topFraction(gate(s, held, all), all, 0.3));
    EXPECT_NE(std::find(st.prefiltered.begin(), st.prefiltered.end(), st.selected), st.prefiltered.end());
    ++selections;
  }
  EXPECT_EQ(selections, 3);  // views 3 to 5
}

TEST(ActiveRun, KmedianFisherIsFisherOnTheKmediansTopFraction) {
  expectFisherOnTheGatesTopFraction(Method::kKmedianFisher, Method::kKmedian,
                                    [](const Scene& s, const auto& held, const auto& all) {
                                      return kmedianGains(s, held, all, s.train, poseAngleScale(s));
                                    });
}

TEST(ActiveRun, FvsFisherIsFisherOnFarthestViewsTopFraction) {
  expectFisherOnTheGatesTopFraction(
      Method::kFvsFisher, Method::kFvs,
      [](const Scene& s, const auto& held, const auto& all) { return fvsScores(s, held, all); });
}

// fisher-kmedian scores every candidate by FisherRF (the first selection's scores are the
// fisher run's: the same model), then takes the k-median gain weighted by those scores.
TEST(ActiveRun, FisherKmedianWeighsTheKmedianGainByFisher) {
  const Scene& s = tinyDataset();
  const ActiveResult r = ActiveRun(s, tinyOptions(Method::kFisherKmedian)).run();
  const ActiveResult f = ActiveRun(s, tinyOptions(Method::kFisher)).run();
  ASSERT_FALSE(r.steps.empty());
  EXPECT_EQ(r.steps[0].fisher_scores, f.steps[0].scores);
  int selections = 0;
  for (const SelectionLog& st : r.steps) {
    if (st.selected < 0) continue;
    const std::vector<int> held(r.selected_views.begin(), r.selected_views.begin() + st.views_before);
    std::vector<int> all;
    for (int v : s.train)
      if (std::find(held.begin(), held.end(), v) == held.end()) all.push_back(v);
    EXPECT_EQ(st.candidates, all);
    ASSERT_EQ(st.fisher_scores.size(), all.size());
    EXPECT_EQ(st.scores, kmedianGains(s, held, all, all, poseAngleScale(s), st.fisher_scores));
    EXPECT_EQ(st.selected, all[argmaxScore(st.scores, all)]);
    ++selections;
  }
  EXPECT_EQ(selections, 3);
}

// adaptive is kmedian-fisher above its clustering threshold and fvs-fisher below it, view
// for view (thresholds either side of the tiny capture's own clustering), and its default
// threshold puts the tiny capture, an even ring, on the farthest-view side.
TEST(ActiveRun, AdaptiveGatesByTheCapturesClustering) {
  const Scene& s = tinyDataset();
  const double c = captureClustering(s);
  auto run = [&](Method m, double threshold) {
    ActiveOptions o = tinyOptions(m);
    o.gate_keep = 0.3;
    o.adaptive_clustering = threshold;
    return ActiveRun(s, o).run().selected_views;
  };
  const std::vector<int> kmed = run(Method::kKmedianFisher, 0), fvs = run(Method::kFvsFisher, 0);
  ASSERT_NE(kmed, fvs) << "the tiny capture must tell the two gates apart for this test to mean anything";
  EXPECT_EQ(run(Method::kAdaptive, c * 0.5 - 1e-9), kmed);
  EXPECT_EQ(run(Method::kAdaptive, c * 2 + 1e-9), fvs);
  EXPECT_LT(c, ActiveOptions{}.adaptive_clustering);
  // usesKmedianGate says the same (what `saresgs active` and `info` print), and refuses a
  // method without a gate.
  ActiveOptions o = tinyOptions(Method::kAdaptive);
  o.adaptive_clustering = c * 0.5;
  EXPECT_TRUE(usesKmedianGate(s, o));
  o.adaptive_clustering = c * 2;
  EXPECT_FALSE(usesKmedianGate(s, o));
  EXPECT_TRUE(usesKmedianGate(s, tinyOptions(Method::kKmedianFisher)));
  EXPECT_FALSE(usesKmedianGate(s, tinyOptions(Method::kFvsFisher)));
  EXPECT_THROW(usesKmedianGate(s, tinyOptions(Method::kFisher)), std::invalid_argument);
}

// The oracle is told the test poses: each step's scores are the k-median gains over the
// test views (not the train views kmedian uses), and it takes the best. Its final fit, as
// every method's, also reports the PSNR of every view of the path, which for the test views
// is the final fit's own evaluation.
TEST(ActiveRun, OracleIsTheKmedianGainOverTheTestPosesAndTheFinalFitCoversThePath) {
  const Scene& s = tinyDataset();
  ASSERT_FALSE(s.test.empty());
  ActiveOptions o = tinyOptions(Method::kOracle);
  o.final_iterations = 30;
  const ActiveResult r = ActiveRun(s, o).run();
  int selections = 0;
  for (const SelectionLog& st : r.steps) {
    if (st.selected < 0) continue;
    const std::vector<int> held(r.selected_views.begin(), r.selected_views.begin() + st.views_before);
    EXPECT_EQ(st.scores, kmedianGains(s, held, st.candidates, s.test, poseAngleScale(s)));
    EXPECT_NE(st.scores, kmedianGains(s, held, st.candidates, s.train, poseAngleScale(s)))
        << "the tiny dataset must tell the two populations apart for this test to mean anything";
    EXPECT_EQ(st.selected, st.candidates[argmaxScore(st.scores, st.candidates)]);
    ++selections;
  }
  EXPECT_EQ(selections, 3);
  ASSERT_TRUE(r.final_fit.has_value());
  ASSERT_EQ(r.final_fit->path.size(), s.views.size());
  for (std::size_t i = 0; i < s.views.size(); ++i) {
    EXPECT_EQ(r.final_fit->path[i].view, static_cast<int>(i));
    EXPECT_TRUE(std::isfinite(r.final_fit->path[i].psnr));
  }
  for (const ViewMetrics& m : r.final_fit->test.views)
    EXPECT_EQ(r.final_fit->path[static_cast<std::size_t>(m.view)].psnr, m.psnr);
}

}  // namespace
}  // namespace saresgs
