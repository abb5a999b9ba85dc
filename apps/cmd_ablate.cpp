// saresgs ablate: runs an ablation grid of active runs and prefilter sweeps as
// independent jobs (listable, shardable, skipped when finished), and merges finished
// jobs into tables, plots and a page. The grid format is in nbv/eval/ablation.h, the
// runner in nbv/eval/ablation_runner.h; this file parses the flags, runs an active job as
// `saresgs active` in this process, and writes the grid's page (report/grid_page.h).
#include <cstdio>
#include <iostream>
#include <sstream>

#include "apps/cli.h"
#include "apps/commands.h"
#include "geometry/error.h"
#include "nbv/eval/ablation.h"
#include "nbv/eval/ablation_runner.h"
#include "report/grid_page.h"

namespace saresgs::apps {

namespace {

struct AblateArgs {
  std::string config, out, shard, inputs;
  bool list = false, allow_partial = false;
};

// Every active job's command line (preset, seed, threads, method_args, a variant's args) is
// parsed when the config is read, so that a bad value stops the grid before any job runs.
void checkJobArguments(const AblationGrid& g, const std::vector<AblationJob>& jobs) {
  for (const AblationJob& j : jobs) {
    if (j.kind != AblationJob::Kind::kActive) continue;
    try {
      checkActiveArguments(j.args);
    } catch (const std::exception& e) {
      std::string field;
      if (g.method_args.count(j.method)) field = "method_args." + j.method;
      for (std::size_t v = 0; v < g.variants.size(); ++v)
        if (g.variants[v].name == j.variant && !g.variants[v].args.empty())
          field += (field.empty() ? "" : " + ") + std::string("variants[") + std::to_string(v) + "].args";
      if (field.empty()) field = "preset/threads/seeds";
      throw InputError(g.source, field, "job " + j.id + ": " + e.what());
    }
  }
}

// Tables, plots, the index and the grid's page for every finished job; 2 when jobs are
// missing and that was not allowed.
int writeSummary(const AblationGrid& g, const std::vector<AblationJob>& jobs, const std::string& out,
                 bool allow_partial) {
  const AblationSummary s = writeAblationSummary(g, jobs, out);
  // The same as one page to look at; a page that cannot be made is said, the tables stand.
  try {
    const GridPageResult r = writeGridPage(out);
    std::cerr << "[ablate] wrote " << r.path << ": open it in a browser\n";
  } catch (const std::exception& e) {
    std::cerr << "[ablate] no report.html: " << e.what() << "\n";
  }
  if (s.missing.empty()) return 0;
  std::cerr << "[ablate] " << s.missing.size() << " jobs not finished";
  if (!allow_partial) std::cerr << " (pass --allow-partial to accept)";
  std::cerr << "\n";
  return allow_partial ? 0 : 2;
}

int runAblate(const AblateArgs& a) {
  const AblationGrid g = readAblationGrid(a.config);
  const std::vector<AblationJob> all = expandGrid(g);
  checkJobArguments(g, all);
  int si = 0, sn = 1;
  if (!a.shard.empty()) std::tie(si, sn) = parseShard(a.shard);
  const std::vector<AblationJob> jobs = shardJobs(all, si, sn);
  if (a.list) {
    for (const auto& j : jobs) {
      std::printf("%s %s\n", jobFinished(a.out, j) ? "[done]" : "[todo]", j.id.c_str());
      if (j.kind == AblationJob::Kind::kActive)
        std::printf("    %s\n", commandLineText(activeJobArgs(j, a.out)).c_str());
      else
        std::printf("    prefilter sweep of %s (in-process)\n", j.scene.c_str());
    }
    return 0;
  }
  const ShardOutcome r = runAblationJobs(g, jobs, a.out, runCli);
  std::cerr << "[ablate] " << r.done << " of " << jobs.size() << " jobs finished"
            << (r.failed ? ", " + std::to_string(r.failed) + " failed" : "") << "\n";
  if (sn > 1) {
    std::cerr << "[ablate] shard " << si << "/" << sn
              << " done; when every shard is, run: saresgs ablate merge --config " << a.config << " --out " << a.out
              << " [--inputs OTHER_OUT,...]\n";
    return r.failed ? 1 : 0;
  }
  const int rc = writeSummary(g, all, a.out, false);
  return r.failed ? 1 : rc;
}

int runMerge(const AblateArgs& a) {
  const AblationGrid g = readAblationGrid(a.config);
  const std::vector<AblationJob> all = expandGrid(g);
  checkJobArguments(g, all);
  std::vector<std::string> inputs;
  std::stringstream ss(a.inputs);
  for (std::string in; std::getline(ss, in, ',');) inputs.push_back(in);
  mergeAblationInputs(all, inputs, a.out);
  return writeSummary(g, all, a.out, a.allow_partial);
}

}  // namespace

void addAblateCommand(CLI::App& app, Action& action) {
  auto a = std::make_shared<AblateArgs>();
  CLI::App* sub = app.add_subcommand(
      "ablate", "Run an ablation grid of active runs and prefilter sweeps; `ablate merge` makes its tables");
  sub->add_option("--config", a->config, "Grid JSON (format: nbv/ablation.h)");
  sub->add_option("--out", a->out, "Output folder (runs/, tables/, plots/, README.md)");
  sub->add_option("--shard", a->shard, "Run only jobs i, i+n, ... (i/n)");
  sub->add_flag("--list", a->list, "Print the jobs (and their `saresgs active` command lines) and exit");
  CLI::App* merge =
      sub->add_subcommand("merge", "Collect finished jobs (from --inputs) into OUT and write the tables and plots");
  merge->add_option("--config", a->config, "Grid JSON")->required();
  merge->add_option("--out", a->out, "Output folder")->required();
  merge->add_option("--inputs", a->inputs, "Comma-separated shard output folders to copy finished jobs from");
  merge->add_flag("--allow-partial", a->allow_partial, "Exit 0 even when some jobs are not finished");
  merge->callback([&action, a] { action = [a] { return runMerge(*a); }; });
  sub->callback([&action, a, sub, merge] {
    if (merge->parsed()) return;
    if (a->config.empty() || a->out.empty()) throw CLI::RequiredError("ablate needs --config and --out");
    action = [a] { return runAblate(*a); };
  });
}

}  // namespace saresgs::apps
