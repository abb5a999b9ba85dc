// saresgs active: one active reconstruction run (the product's main job).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>

#include "apps/cli_checks.h"
#include "splat/thread_limit.h"
#include "apps/commands.h"
#include "apps/memory_budget.h"
#include "splat/bench/machine.h"
#include "nbv/prefilter_options.h"
#include "apps/progress.h"
#include "apps/settings_flags.h"
#include "geometry/scene/dataset_checks.h"
#include "geometry/io/atomic_file.h"
#include "geometry/io/json_file.h"
#include "nbv/active_run.h"
#include "nbv/eval/run_files.h"
#include "nbv/active_settings.h"
#include "nbv/preset.h"
#include "nbv/run_report.h"
#include "splat/raster_execution.h"
#include "report/run_page.h"
#include "splat/train/test_renders.h"

namespace saresgs::apps {

namespace {

namespace fs = std::filesystem;

// What describes where the run reads and writes, beside its settings (nbv/active_settings.h).
struct ActiveArgs {
  std::string dataset, out, replay, background;
  int downscale = 1;
  bool resume = false;
  std::optional<int> renamed_iterations;
  std::optional<double> memory_budget_gb;
  ActiveSettings settings;
};

// The run's options: the preset, then every setting given on the command line.
ActiveOptions activeOptions(const ActiveArgs& a) {
  if (a.renamed_iterations)
    throw std::invalid_argument(
        "--iterations is now --min-iterations: the loop trains at least that many iterations in all, the last phase "
        "what is left and never less than views x --interval (results.json: iterations, phase_iterations)");
  return activeOptionsFrom(a.settings, a.dataset, SettingNaming::kFlag);
}

void printSummary(const RunReport& r, const std::string& out) {
  std::string phases;
  if (r.phase_iterations)
    for (int p : *r.phase_iterations) phases += (phases.empty() ? "" : " + ") + std::to_string(p);
  std::printf("\n%s run, preset %s, seed %llu, %d iterations in the loop (%s; at least %d asked), %zu views\n",
              r.method.c_str(), r.preset.c_str(), static_cast<unsigned long long>(r.seed), r.iterations, phases.c_str(),
              r.options.total_iterations, r.selected_view_indices.size());
  std::printf("%-44s %8s %8s %8s %10s %10s %10s\n", "model", "PSNR", "SSIM", "AUSE", "select s", "train s", "total s");
  std::printf("%-44s %8.2f %8.4f %8s %10.1f %10.1f %10.1f\n", "in the loop (paper's protocol)", r.psnr, r.ssim,
              r.ause ? std::to_string(*r.ause).substr(0, 6).c_str() : "n/a", r.seconds.selection(), r.seconds.training,
              r.end_to_end_seconds);
  if (r.final_fit) {
    char label[64];
    std::snprintf(label, sizeof label, "final fit on these views (%d it%s)", r.final_fit->iterations,
                  r.final_fit->residual ? ", residual" : "");
    std::printf("%-44s %8.2f %8.4f\n", label, r.final_fit->psnr, r.final_fit->ssim);
    if (r.final_fit_views && r.final_fit->residual) {
      std::snprintf(label, sizeof label, "plain refit of these views (%d it)", r.final_fit_views->iterations);
      std::printf("%-44s %8.2f %8.4f\n", label, r.final_fit_views->psnr, r.final_fit_views->ssim);
    }
  }
  const bool plain_file = r.final_fit && r.final_fit->residual && r.final_fit_views;
  std::printf("wrote %s/results.json, cameras.png, test_renders/, point_cloud.ply%s%s\n", out.c_str(),
              r.final_fit ? ", final_fit.ply" : "", plain_file ? ", final_fit_views.ply" : "");
}

// The run's HTML page (report/run_page.h). The run's files are written by now: a page
// that cannot be made is said, not a failed run.
void writeReportPage(const std::string& out, const Scene& scene, int threads) {
  try {
    RunPageOptions page;
    page.threads = threads;
    const RunPageResult r = writeRunPage(out, &scene, page);
    for (const std::string& m : r.missing) std::cerr << "report: " << m << "\n";
    std::printf("wrote %s (%.1f MB): open it in a browser\n", r.path.c_str(),
                static_cast<double>(r.bytes) / (1024.0 * 1024.0));
  } catch (const std::exception& e) {
    std::cerr << "report: no report.html: " << e.what() << "\n";
  }
}

int runActive(const ActiveArgs& a) {
  const auto thread_limit = limitThreads(a.settings.threads);
  ActiveOptions opt = activeOptions(a);
  DatasetOptions dopt;
  dopt.load.downscale = a.downscale;
  if (!a.background.empty()) dopt.background = parseBackground(a.background, "--background");
  const Scene scene = loadDataset(a.dataset, dopt);
  // What the run says of its data before it starts, kept for results.json's "warnings"
  // (the report shows them): the dataset's checks and the background. (The memory
  // budget's line names this machine's memory: printed, not kept, so that the same run
  // on two machines writes the same results.json.)
  std::string said = formatWarnings(checkDataset(scene, opt.trainer.raster.near_plane)) + backgroundWarning(scene);
  std::cerr << said;
  if (!a.replay.empty()) {
    const RunReport replayed = runReportFromJson(readJsonFile(a.replay), a.replay);
    opt.replay = replaySequence(scene, replayed, a.replay);
    std::cerr << "replaying the " << opt.replay.size() << " views of " << a.replay << " (" << replayed.method
              << ", seed " << replayed.seed << ") in their order\n";
  }
  fs::create_directories(a.out);
  if (const int n = removeStaleTemporaries(a.out))
    std::cerr << "removed " << n << " temporaries left by a killed run\n";
  const std::string ckpt = a.out + "/checkpoint.json";
  if (!a.resume && fs::exists(ckpt))
    throw std::runtime_error(ckpt + " exists: pass --resume to continue that run, or choose another --out");
  {
    // The views it will train on: max_views of the candidates (their sizes, as the largest
    // ones are not known before selection: the first ones); the models it holds: the
    // loop's, the final fit's and, for residual methods, the plain refit's.
    std::vector<int> trained(
        scene.train.begin(),
        scene.train.begin() +
            std::min<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(scene.train.size()), std::max(opt.max_views, 1)));
    const std::size_t initial = initialModelSize(scene, opt.trainer);
    const int models = 1 + (opt.final_iterations > 0 ? (finalFitIsResidual(opt) && opt.plain_refit ? 2 : 1) : 0);
    std::size_t cap = opt.trainer.densify.max_gaussians;
    const std::string budget =
        applyMemoryBudget(estimateTrainingMemory(scene, trained, scene.test.empty() ? scene.train : scene.test, initial,
                                                 opt.trainer.max_sh_degree, models),
                          memoryBudgetBytes(a.memory_budget_gb), a.memory_budget_gb.has_value(), cap);
    std::cerr << budget;
    opt.trainer.densify.max_gaussians = opt.final_trainer.densify.max_gaussians = cap;
  }
  const bool resuming = a.resume && fs::exists(ckpt);
  ActiveRun run(scene, opt, ckpt);
  if (resuming) std::cerr << "resuming from " << ckpt << "\n";
  std::cerr << "active run: " << toString(opt.method) << " on " << a.dataset << " (" << scene.train.size()
            << " candidates, " << scene.test.size() << " test views), preset " << a.settings.preset << ", seed "
            << opt.seed << "\n";
  if (opt.method == Method::kAdaptive) {
    const bool kmedian = usesKmedianGate(scene, opt);
    std::cerr << "adaptive: capture clustering " << captureClustering(scene) << (kmedian ? " > " : " <= ")
              << opt.adaptive_clustering << ", so Fisher ranks the top " << opt.gate_keep * 100 << " % by "
              << (kmedian ? "k-median gain (kmedian-fisher)" : "distance to the nearest held view (fvs-fisher)")
              << "\n";
  }
  Progress progress;
  // Resident memory at the start of every phase (per number of views held): an active run
  // holds its buffers from phase to phase, so this should grow only with the model.
  nlohmann::json phase_memory = nlohmann::json::array();
  std::string last_phase;
  const auto note_memory = [&](const std::string& phase, int views, std::size_t gaussians) {
    if (phase == last_phase) return;
    last_phase = phase;
    phase_memory.push_back(
        {{"phase", phase}, {"views", views}, {"gaussians", gaussians}, {"rss_bytes", currentRssBytes()}});
  };
  const ActiveResult r = run.run([&](const ActiveProgress& p) {
    note_memory(std::string(toString(p.phase)) + " " + std::to_string(p.views), p.views, p.gaussians);
    char detail[200];
    std::snprintf(detail, sizeof detail, "%s %d/%d  views %d/%d  loss %.4f  PSNR %.2f  Gaussians %zu",
                  toString(p.phase), p.phase_done, p.phase_total, p.views, p.max_views, p.loss, p.psnr, p.gaussians);
    // A phase is a phase of its own per number of views held (a log line each).
    progress.update("active", p.iteration, p.total_iterations, detail,
                    std::string(toString(p.phase)) + " " + std::to_string(p.views));
  });
  const Trainer& t = run.trainer();
  writeTestRenders(t, r.test, a.out + "/test_renders");
  writeRunFiles(run, r, scene, a.out);
  const RunReport report = makeRunReport(
      scene, opt, r,
      {a.dataset, a.settings.preset, a.replay, t.gaussians().size(), rasterThreadCount(opt.trainer.raster.execution)});
  note_memory("end", static_cast<int>(r.selected_views.size()), t.gaussians().size());
  nlohmann::json results = toJson(report);
  // Machine state, like the timings: not part of what a resumed run must reproduce.
  results["memory"] = {{"peak_rss_bytes", peakRssBytes()}, {"rss_at_phase_start_this_process", phase_memory}};
  results["settings"] = activeSettingsJson(a.settings);
  results["warnings"] = nlohmann::json::array();
  for (std::size_t p = 0, q; p < said.size(); p = q + 1) {
    q = said.find('\n', p);
    if (q == std::string::npos) q = said.size();
    if (q > p) results["warnings"].push_back(said.substr(p, q - p));
  }
  writeFileAtomic(a.out + "/results.json", results.dump(2) + "\n");
  printSummary(report, a.out);
  writeReportPage(a.out, scene, a.settings.threads);
  std::printf("peak resident memory %.0f MB (this process)\n", peakRssBytes() / (1024.0 * 1024.0));
  return 0;
}

}  // namespace

namespace {

// The subcommand and its options, filling `a`.
CLI::App* addActiveOptions(CLI::App& app, const std::shared_ptr<ActiveArgs>& a) {
  CLI::App* sub = app.add_subcommand("active", "Active reconstruction: select views one by one while training");
  sub->add_option("--dataset", a->dataset, "COLMAP, Blender or `saresgs scene` folder")->required();
  sub->add_option("--out", a->out, "Output folder")->required();
  sub->add_option("--iterations", a->renamed_iterations, "Renamed --min-iterations")->group("");
  sub->add_option("--memory-budget", a->memory_budget_gb,
                  "GB this run may use: refused before it starts if its images and initial models do not fit, the "
                  "models capped to fit (default: refused only beyond what the machine has available)")
      ->check(CLI::Range(0.001, 1e6));
  addSettingFlags(sub, a->settings, activeSettingFields());
  sub->add_option("--replay", a->replay,
                  "Fixed order: train with this method's training on the views of another run's results.json, in their "
                  "order, instead of selecting (the paper's ablation)");
  addRanged(sub, "--downscale", a->downscale, "Image downscale factor", 1, 64);
  sub->add_option("--background", a->background, kBackgroundHelp)->check(backgroundValue());
  sub->add_flag("--resume", a->resume, "Continue the run in OUT from its checkpoint");
  return sub;
}

}  // namespace

void addActiveCommand(CLI::App& app, Action& action) {
  auto a = std::make_shared<ActiveArgs>();
  CLI::App* sub = addActiveOptions(app, a);
  sub->callback([&action, a] { action = [a] { return runActive(*a); }; });
}

void checkActiveArguments(const std::vector<std::string>& args) {
  auto a = std::make_shared<ActiveArgs>();
  CLI::App app;
  addActiveOptions(app, a);
  std::vector<std::string> argv{"active"};
  argv.insert(argv.end(), args.begin(), args.end());
  if (std::find(args.begin(), args.end(), "--out") == args.end()) argv.insert(argv.end(), {"--out", "."});
  try {
    app.parse(std::vector<std::string>(argv.rbegin(), argv.rend()));
  } catch (const CLI::ParseError& e) {
    throw std::invalid_argument(e.what());
  }
  (void)activeOptions(*a);
}

}  // namespace saresgs::apps
