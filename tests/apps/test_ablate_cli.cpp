// `saresgs ablate` as a user runs it: two shard processes into two folders, a merge, the
// tables and plots it writes, and a killed runner that restarts without redoing jobs.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <fstream>
#include <tuple>
#include <vector>

#include "common/run_command.h"
#include "common/test_support.h"
#include "geometry/image/image.h"

using saresgs::test::readBytes;
using saresgs::test::TempDir;
using saresgs::test::writeBytes;
namespace fs = std::filesystem;

namespace {

using Result = saresgs::test::CommandResult;

Result shell(const std::string& script) { return saresgs::test::runCommand("bash -c '" + script + "'"); }

std::string cli() { return SARESGS_CLI; }

int count(const std::string& s, const std::string& what) {
  int n = 0;
  for (std::size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

// A grid small enough for a test: one generated 64x48 scene, two cheap methods, two
// seeds, 5 views with a few iterations each, and a prefilter sweep.
std::string writeGrid(const TempDir& d) {
  const std::string grid = d.file("grid.json");
  writeBytes(grid, R"({
    "scenes": [{"name": "tiny", "dataset": ")" +
                       d.file("tiny") + R"(", "layout": "object"}],
    "methods": ["random", "fvs"],
    "seeds": [0, 1],
    "threads": 1,
    "variants": [{"name": "default", "args": ["--max-views", "5", "--interval", "3", "--min-iterations", "30", "--final-iterations", "20"]}],
    "tables": [{"name": "criteria", "title": "Prefilter criteria", "methods": ["random", "fvs"]}],
    "sweep": {"views": [4], "encodings": ["hash:11", "hash:16", "exact"], "lifting": "depth", "timing_repeats": 1}
  })");
  // Small images keep the generated scene and the runs fast.
  const Result r = shell(cli() + " scene --layout object --views 12 --width 64 --height 48 --out " + d.file("tiny"));
  EXPECT_EQ(r.code, 0) << r.output;
  return grid;
}

}  // namespace

TEST(AblateCli, TwoShardsAndAMergeMakeTablesAndPlots) {
  TempDir d;
  const std::string grid = writeGrid(d);
  const std::string a = d.file("shard0"), b = d.file("shard1");
  Result r = shell(cli() + " ablate --config " + grid + " --out " + a + " --list");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(count(r.output, "[todo]"), 5) << r.output;  // 1 sweep + 2 methods x 2 seeds
  EXPECT_NE(r.output.find("saresgs active --dataset"), std::string::npos) << r.output;

  // Two processes at once, each writing its own folder, as two machines would.
  r = shell(cli() + " ablate --config " + grid + " --out " + a + " --shard 0/2 > " + d.file("log0") + " 2>&1 & " +
            cli() + " ablate --config " + grid + " --out " + b + " --shard 1/2 > " + d.file("log1") +
            " 2>&1; s1=$?; wait $!; s0=$?; " + "exit $((s0 + s1))");
  ASSERT_EQ(r.code, 0) << readBytes(d.file("log0")) << readBytes(d.file("log1"));
  EXPECT_NE(readBytes(d.file("log1")).find("ablate merge"), std::string::npos);  // the shard says what comes next

  // Without the other shard's jobs the merge is partial and says so.
  r = shell(cli() + " ablate merge --config " + grid + " --out " + a);
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("not finished"), std::string::npos) << r.output;
  r = shell(cli() + " ablate merge --config " + grid + " --out " + a + " --inputs " + d.file("nowhere"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.output.find(d.file("nowhere")), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("not a folder"), std::string::npos) << r.output;
  r = shell(cli() + " ablate merge --config " + grid + " --out " + a + " --inputs " + b);
  ASSERT_EQ(r.code, 0) << r.output;

  const std::string results = readBytes(a + "/tables/results.md");
  EXPECT_NE(results.find("| tiny | random | 2 |"), std::string::npos) << results;
  EXPECT_NE(results.find("| tiny | fvs | 2 |"), std::string::npos) << results;
  const std::string csv = readBytes(a + "/tables/results.csv");
  EXPECT_EQ(count(csv, "\n"), 3) << csv;  // header + 2 rows
  EXPECT_NE(csv.find("PSNR_mean,PSNR_std"), std::string::npos) << csv;
  EXPECT_TRUE(fs::exists(a + "/tables/criteria.md"));
  EXPECT_TRUE(fs::exists(a + "/tables/time.csv"));
  const std::string sweep = readBytes(a + "/tables/prefilter_sweep.md");
  EXPECT_EQ(count(sweep, "| tiny |"), 2 * 2 * 3) << sweep;  // sets x scores x encodings
  // The object layout sweeps the outdoor grid (m = 2), and says so with each hash's load.
  EXPECT_NE(sweep.find("| tiny | outdoor r64 m2, "), std::string::npos) << sweep;
  for (const char* p : {"psnr", "final_fit_psnr", "final_fit_per_view", "psnr_vs_views", "psnr_vs_selection_time",
                        "prefilter_sweep_tiny"}) {
    const saresgs::Image8 img = saresgs::readImage(a + "/plots/" + p + ".png");
    EXPECT_GT(img.width, 100) << p;
  }
  EXPECT_NE(readBytes(a + "/README.md").find("plots/psnr.png"), std::string::npos);
}

TEST(AblateCli, AKilledRunnerRestartsWithoutRedoingFinishedJobs) {
  TempDir d;
  const std::string grid = writeGrid(d);
  const std::string out = d.file("out");
  // Kill the runner (SIGKILL, no clean-up) as soon as its second job has finished.
  const std::string second = out + "/runs/tiny__random__default__s0/results.json";
  Result r =
      shell(cli() + " ablate --config " + grid + " --out " + out + " > " + d.file("log") + " 2>&1 & pid=$!; " +
            "for i in $(seq 1 600); do [ -f " + second + " ] && break; sleep 0.1; done; kill -9 $pid; wait $pid; true");
  ASSERT_TRUE(fs::exists(second)) << readBytes(d.file("log"));
  const auto sweep_file = out + "/runs/tiny__prefilter-sweep/sweep.json";
  ASSERT_TRUE(fs::exists(sweep_file));
  const auto t_sweep = fs::last_write_time(sweep_file), t_second = fs::last_write_time(second);
  const std::string sweep_bytes = readBytes(sweep_file), second_bytes = readBytes(second);

  r = shell(cli() + " ablate --config " + grid + " --out " + out);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(count(r.output, "finished before, skipped"), 2) << r.output;
  EXPECT_EQ(fs::last_write_time(sweep_file), t_sweep);
  EXPECT_EQ(fs::last_write_time(second), t_second);
  EXPECT_EQ(readBytes(sweep_file), sweep_bytes);
  EXPECT_EQ(readBytes(second), second_bytes);
  // A third start finds everything done and only rewrites the summary.
  r = shell(cli() + " ablate --config " + grid + " --out " + out);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(count(r.output, "finished before, skipped"), 5) << r.output;
  EXPECT_TRUE(fs::exists(out + "/tables/results.md"));
}

// The GNU-parallel path of results/README.md: two shards into one output folder at once,
// then a merge; every job runs exactly once (a finished job's folder holds one result).
TEST(AblateCli, GnuParallelShardsIntoOneFolderThenMerge) {
  TempDir d;
  const std::string grid = writeGrid(d);
  const std::string out = d.file("out");
  Result r = shell("parallel --version");
  ASSERT_EQ(r.code, 0) << "GNU parallel is missing (bash scripts/install_deps.sh installs it): " << r.output;
  r = shell("parallel --will-cite -j 2 --halt now,fail=1 " + cli() + " ablate --config " + grid + " --out " + out +
            " --shard {}/2 ::: 0 1");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(count(r.output, "shard 0/2 done"), 1) << r.output;
  EXPECT_EQ(count(r.output, "shard 1/2 done"), 1) << r.output;
  r = shell(cli() + " ablate merge --config " + grid + " --out " + out);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("from 5 of 5 jobs"), std::string::npos) << r.output;
  int results = 0;
  for (const auto& e : fs::recursive_directory_iterator(out + "/runs"))
    results += e.path().filename() == "results.json" || e.path().filename() == "sweep.json";
  EXPECT_EQ(results, 5);
  EXPECT_TRUE(fs::exists(out + "/tables/paired.csv"));
  EXPECT_EQ(readBytes(out + "/tables/paired.csv")
                .rfind("scene,method,baseline,metric,mean_diff,ci_low,ci_high,n,win_rate\n", 0),
            0u);
}

// Two runners of the whole grid on one folder at once (a shard started twice, an array
// task resubmitted beside the old one) while merges run: each job runs exactly once (its
// job lock, runs/<job>.lock), both runners end with every job finished, and the tables
// equal those of a single clean run.
TEST(AblateCli, TwoRunnersOnOneFolderRunEachJobOnceWhileMergesRun) {
  TempDir d;
  const std::string grid = writeGrid(d);
  const std::string out = d.file("out"), clean = d.file("clean");
  Result r = shell(cli() + " ablate --config " + grid + " --out " + out + " > " + d.file("logA") + " 2>&1 & a=$!; " +
                   cli() + " ablate --config " + grid + " --out " + out + " > " + d.file("logB") + " 2>&1 & b=$!; " +
                   "while kill -0 $a 2>/dev/null || kill -0 $b 2>/dev/null; do " + cli() + " ablate merge --config " +
                   grid + " --out " + out + " --allow-partial > /dev/null 2>&1 || exit 9; sleep 0.3; done; " +
                   "wait $a; sa=$?; wait $b; exit $((sa + $?))");
  const std::string logs = readBytes(d.file("logA")) + readBytes(d.file("logB"));
  ASSERT_EQ(r.code, 0) << logs;
  for (const char* job : {"tiny__prefilter-sweep", "tiny__random__default__s0", "tiny__random__default__s1",
                          "tiny__fvs__default__s0", "tiny__fvs__default__s1"})
    EXPECT_EQ(count(logs, std::string(" ") + job + "\n"), 1) << job << " should start once:\n" << logs;
  r = shell(cli() + " ablate --config " + grid + " --out " + clean);
  ASSERT_EQ(r.code, 0) << r.output;
  r = shell(cli() + " ablate merge --config " + grid + " --out " + out);
  ASSERT_EQ(r.code, 0) << r.output;
  // Same numbers as the clean run (the tables hold no timings but time.csv).
  for (const char* t : {"results.csv", "paired.csv", "criteria.csv"})
    EXPECT_EQ(readBytes(out + "/tables/" + t), readBytes(clean + "/tables/" + t)) << t;
}

// Every job's `saresgs active` arguments are checked when the config is read: a bad value
// in a variant's args or in method_args stops the grid before any job runs, naming the
// config and the field.
TEST(AblateCli, JobArgumentsAreCheckedWhenTheConfigIsRead) {
  TempDir d;
  const std::string grid = d.file("grid.json");
  for (const auto& [extra, field, says] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {R"("variants": [{"name": "v", "args": ["--max-views", "-3"]}])", "variants[0].args", "--max-views"},
           {R"("variants": [{"name": "v", "args": ["--nosuch"]}])", "variants[0].args", "--nosuch"},
           {R"("variants": [{"name": "v", "args": ["--iterations", "300"]}])", "variants[0].args", "--min-iterations"},
           {R"("method_args": {"fvs": ["--fisher-lambda", "-1"]})", "method_args.fvs", "--fisher-lambda"},
           {R"("method_args": {"random": ["--prefilter-set", "sphere"]})", "method_args.random", "sphere"},
           {R"("variants": [{"name": "v", "methods": ["fvs"], "args": ["--residual-ranking", "colour"]}])",
            "variants[0].args", "colour"},
       }) {
    writeBytes(grid, R"({"scenes": [{"name": "s", "dataset": ")" + d.file("s") + R"(", "layout": "object"}],
                        "methods": ["random", "fvs"], )" +
                         extra + "}");
    for (const std::string& cmd : {" ablate --config " + grid + " --out " + d.file("o"),
                                   " ablate --config " + grid + " --out " + d.file("o") + " --list",
                                   " ablate merge --config " + grid + " --out " + d.file("o")}) {
      const Result r = shell(cli() + cmd);
      EXPECT_NE(r.code, 0) << extra;
      EXPECT_NE(r.output.find(grid), std::string::npos) << extra << ": " << r.output;
      EXPECT_NE(r.output.find(field), std::string::npos) << extra << ": " << r.output;
      EXPECT_NE(r.output.find(says), std::string::npos) << extra << ": " << r.output;
    }
    EXPECT_FALSE(fs::exists(d.path() / "s")) << "no dataset generated";
    EXPECT_FALSE(fs::exists(d.path() / "o" / "runs")) << "no job ran";
  }
}

// The paper's fixed-order ablation in a grid: a variant that replays fisher's views trains
// resgs on them. Its job comes before fisher's in the job order, so the runner puts it at
// the back of the queue until fisher's run is there; the replayed sequence is fisher's,
// and the tables carry the plain refit as its own metric.
TEST(AblateCli, AReplayVariantTrainsOnTheReplayedRunsViewsOnceThatRunIsFinished) {
  TempDir d;
  const std::string grid = d.file("grid.json");
  const std::string small =
      R"("--max-views", "5", "--interval", "3", "--min-iterations", "30", "--final-iterations", "20")";
  writeBytes(grid, R"({
    "scenes": [{"name": "tiny", "dataset": ")" +
                       d.file("tiny") + R"(", "layout": "object"}],
    "methods": ["resgs", "fisher"],
    "seeds": [0],
    "threads": 1,
    "variants": [{"name": "default", "args": [)" +
                       small + R"(]},
                 {"name": "replay-fisher", "methods": ["resgs"], "replay": "fisher", "args": [)" +
                       small + R"(]}]
  })");
  Result r = shell(cli() + " scene --layout object --views 12 --width 64 --height 48 --out " + d.file("tiny"));
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string out = d.file("o");
  r = shell(cli() + " ablate --config " + grid + " --out " + out + " --list");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("--replay " + out + "/runs/tiny__fisher__default__s0/results.json"), std::string::npos)
      << r.output;
  r = shell(cli() + " ablate --config " + grid + " --out " + out + " 2>&1");
  ASSERT_EQ(r.code, 0) << r.output;
  // fisher ran before the replay, though listed after it.
  const std::size_t fisher_at = r.output.find("tiny__fisher__default__s0\n"),
                    replay_at = r.output.find("tiny__resgs__replay-fisher__s0\n");
  ASSERT_NE(fisher_at, std::string::npos) << r.output;
  ASSERT_NE(replay_at, std::string::npos) << r.output;
  EXPECT_LT(fisher_at, replay_at) << r.output;
  auto views = [&](const std::string& job) {
    const nlohmann::json j = nlohmann::json::parse(readBytes(out + "/runs/" + job + "/results.json"));
    return std::make_pair(j["selected_view_indices"].get<std::vector<int>>(), j);
  };
  const auto [fisher_views, fisher] = views("tiny__fisher__default__s0");
  const auto [replay_views, replay] = views("tiny__resgs__replay-fisher__s0");
  EXPECT_EQ(replay_views, fisher_views);
  EXPECT_EQ(replay["replay_of"], out + "/runs/tiny__fisher__default__s0/results.json");
  EXPECT_EQ(replay["final_fit"]["residual"], true);
  const std::string paired = readBytes(out + "/tables/paired.csv");
  EXPECT_NE(paired.find("tiny,resgs (replay-fisher),fisher,plain_refit_psnr"), std::string::npos) << paired;
  // Replaying fisher's views plainly is fisher's own plain refit: the difference is 0.
  EXPECT_NE(paired.find("tiny,resgs (replay-fisher),fisher,plain_refit_psnr,0.000"), std::string::npos) << paired;
  // A replay of a method the grid does not run is refused when the config is read.
  writeBytes(grid, R"({"scenes": [{"name": "tiny", "dataset": ")" + d.file("tiny") + R"("}], "methods": ["resgs"],
    "seeds": [0], "variants": [{"name": "default"}, {"name": "r", "replay": "fisher"}]})");
  r = shell(cli() + " ablate --config " + grid + " --out " + d.file("o2") + " --list 2>&1");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.output.find("variants"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("tiny__fisher__default__s0"), std::string::npos) << r.output;
}
