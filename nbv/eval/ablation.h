#pragma once
// The ablation grid (`saresgs ablate`): a JSON config expands into independent jobs,
// (scene x method x variant x seed) active runs plus one prefilter sweep per scene; each
// job owns a folder under OUT/runs/ and is finished when its result file is there, so a
// restarted runner skips it and shards (every n-th job) can run anywhere and be merged.
// The finished jobs' results turn into the tables (Markdown + CSV) and plots of the
// results section.
//
// Config (paths relative to the working directory):
//   {
//     "preset": "quick", "threads": 0,
//     "scenes": [{"name": "room360", "dataset": "out/builtin", "layout": "room360"}, ...],
//     "methods": ["random", "fisher", "sa-hash", "sa-resgs"],
//     "seeds": [0, 1],
//     "method_seeds": {"sa-hash": [0]},   (optional: fewer seeds for a method, among "seeds")
//     "method_args": {"sa-hash": ["--time-exhaustive-fisher"]},            (optional)
//     "variants": [{"name": "beta0.05", "methods": ["sa-resgs"],             (optional)
//                   "args": ["--residual-beta", "0.05"]},
//                  {"name": "replay-fisher", "methods": ["resgs"], "replay": "fisher"}],
//     "tables": [{"name": "components", "title": "...", "methods": [...],  (optional)
//                 "variants": [...]}],
//     "sweep": {"scenes": ["room360"], "views": [4, 8, 12], "lifting": "flow"} (optional)
//   }
// A scene with a "layout" is generated with `saresgs scene` when its dataset is missing
// (with "scene_seed": N, `--seed N`: another capture of the same type).
// Without "variants" every method runs once as variant "default". A variant with "replay"
// trains its methods on the view sequence of the replayed method's default run of the
// same scene and seed (`saresgs active --replay`, the paper's fixed-order ablation); the
// runner starts such a job once that run is finished.
#include <nlohmann/json.hpp>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "geometry/image/image.h"
#include "nbv/eval/paired_stats.h"
#include "nbv/eval/prefilter_sweep.h"
#include "nbv/run_report.h"

namespace saresgs {

struct AblationScene {
  std::string name, dataset, layout;  // layout: empty = the dataset must exist
  std::uint64_t scene_seed = 0;       // saresgs scene --seed when generated ("scene_seed")
};

struct AblationVariant {
  std::string name = "default";
  std::vector<std::string> methods;  // empty: every method
  std::vector<std::string> args;     // extra `saresgs active` arguments
  std::string replay;                // a method whose default run's views are replayed
};

struct AblationTableSpec {
  std::string name, title;
  std::vector<std::string> methods, variants;  // empty: all
};

struct AblationGrid {
  std::string source;  // the config file, for messages
  std::string preset = "quick";
  int threads = 0;
  std::vector<AblationScene> scenes;
  std::vector<std::string> methods;
  std::vector<std::uint64_t> seeds;
  std::map<std::string, std::vector<std::uint64_t>> method_seeds;  // overrides `seeds` per method
  std::map<std::string, std::vector<std::string>> method_args;
  std::vector<AblationVariant> variants;
  std::vector<AblationTableSpec> tables;
  std::optional<SweepSpec> sweep;
};

// Throws InputError naming the file and the field on a malformed config; every method,
// sweep set, encoding, score and lifting name is checked here, before any job runs.
AblationGrid readAblationGrid(const std::string& path);

struct AblationJob {
  enum class Kind { kActive, kSweep };
  Kind kind = Kind::kActive;
  std::string id;  // folder name under OUT/runs
  std::string scene, method, variant;
  std::uint64_t seed = 0;
  std::vector<std::string> args;  // `saresgs active` arguments, --out and --replay excluded
  std::string replay_of;          // the id of the job whose views this one replays
};

// Every job of the grid in a fixed order (sweeps first, then scene, method, variant, seed).
std::vector<AblationJob> expandGrid(const AblationGrid& g);
// Jobs i, i + n, i + 2n, ... of `jobs`. Throws std::invalid_argument unless 0 <= i < n.
std::vector<AblationJob> shardJobs(const std::vector<AblationJob>& jobs, int i, int n);
// Parses "i/n".
std::pair<int, int> parseShard(const std::string& text);

// Whether variant `v` runs for `method` (an empty method list: every method).
bool variantApplies(const AblationVariant& v, const std::string& method);
// How a run is named in tables and plots: "method", or "method (variant)".
std::string runLabel(const std::string& method, const std::string& variant);

std::string jobFolder(const std::string& out, const AblationJob& j);      // OUT/runs/<id>
std::string jobResultFile(const std::string& out, const AblationJob& j);  // results.json or sweep.json
bool jobFinished(const std::string& out, const AblationJob& j);
// The results file a replay job replays (empty for other jobs).
std::string replaySource(const std::string& out, const AblationJob& j);

// A finished job's result: the run report of an active job, the sweep report of a sweep.
struct JobResult {
  AblationJob job;
  RunReport run;
  SweepReport sweep;
};
// The finished jobs' result files, in job order; InputError names a malformed file.
std::vector<JobResult> loadFinishedJobs(const std::string& out, const std::vector<AblationJob>& jobs);

struct Table {
  std::string name, title;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::string markdown() const;
  std::string csv() const;
};

// The results tables (nbv/eval/ablation_tables.cpp), each left out when it would be
// empty: PSNR/SSIM/AUSE per scene and method (mean +- std over seeds), the config's named
// tables, PSNR against the number of views, the time breakdown, the prefilter sweep, the
// paired differences and the final fit's PSNR per test view.
std::vector<Table> ablationTables(const AblationGrid& g, const std::vector<JobResult>& results);
Table resultsTable(const AblationGrid& g, const std::vector<JobResult>& results);
Table namedTable(const AblationGrid& g, const AblationTableSpec& spec, const std::vector<JobResult>& results);
Table psnrVsViewsTable(const AblationGrid& g, const std::vector<JobResult>& results);
Table timeTable(const AblationGrid& g, const std::vector<JobResult>& results);
Table finalFitPerViewTable(const AblationGrid& g, const std::vector<JobResult>& results);
Table sweepTable(const std::vector<JobResult>& results);
// Paired differences (nbv/eval/paired_stats.h) of every method against random, fisher and
// fvs (those in the grid), per scene, for the final-fit PSNR (the method's training), the
// plain refit's PSNR (selection alone), the in-loop PSNR and the in-loop model's AUSE
// (lower is better; no per-view win rate, "n/a"):
// columns scene, method, baseline, metric, mean_diff, ci_low, ci_high, n, win_rate; an
// interval over a single seed is "undefined".
Table pairedTable(const AblationGrid& g, const std::vector<JobResult>& results);
// The question a selector has to answer: on each scene, its final-fit PSNR against the
// better of fisher and fvs there (fisher when fisher - fvs, paired over their common
// seeds, is >= 0 on average), paired by seed. Empty unless the grid has both baselines.
struct BetterBaselineDifference {
  std::string scene, baseline, method;  // method: runLabel (variants are their own rows)
  PairedDifference d;
};
std::vector<BetterBaselineDifference> againstBetterBaseline(const AblationGrid& g,
                                                            const std::vector<JobResult>& results);
// Its table: scene, baseline, method, mean_diff, ci_low, ci_high, n, verdict (above or
// below the baseline, "interval clear of 0" when it is).
Table betterBaselineTable(const AblationGrid& g, const std::vector<JobResult>& results);

struct NamedPlot {
  std::string name;  // file stem
  Image8 image;
};
// PSNR per method and scene, PSNR against views, PSNR against selection time, and the
// sweep's ranking error against scoring time (nbv/eval/ablation_plots.cpp).
std::vector<NamedPlot> ablationPlots(const AblationGrid& g, const std::vector<JobResult>& results);

// Mean and sample standard deviation (0 for one value); NaN-free for empty input (0, 0).
std::pair<double, double> meanStd(const std::vector<double>& v);

}  // namespace saresgs
