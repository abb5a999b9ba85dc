// saresgs train: plain 3DGS (optionally with residual supervision) on all train views of
// a dataset; writes results.json, test renders beside their ground truth, and the .ply.
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <optional>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "apps/cli_checks.h"
#include "splat/thread_limit.h"
#include "apps/commands.h"
#include "apps/memory_budget.h"
#include "splat/bench/machine.h"
#include "apps/progress.h"
#include "apps/settings_flags.h"
#include "apps/view_list.h"
#include "geometry/scene/dataset_checks.h"
#include "geometry/error.h"
#include "geometry/io/atomic_file.h"
#include "geometry/scene/cameras_json.h"
#include "geometry/scene/scene.h"
#include "splat/model_frame.h"
#include "splat/ply.h"
#include "splat/raster_execution.h"
#include "splat/train/schedule.h"
#include "splat/train/test_renders.h"
#include "splat/train/train_settings.h"
#include "splat/train/trainer.h"

namespace saresgs::apps {

namespace {

namespace fs = std::filesystem;

// Where the training reads and writes, beside its settings (splat/train/train_settings.h).
struct TrainArgs {
  std::string dataset, out;
  int iterations = 3000;
  int downscale = 1;
  int checkpoint_every = 1000;
  bool resume = false;
  std::string views, background;
  std::optional<double> memory_budget_gb;
  TrainSettings settings;
  TrainerOptions opt;  // made from `settings` when the command runs
};

std::string shortCount(std::size_t n) {
  char buf[32];
  if (n >= 10000)
    std::snprintf(buf, sizeof buf, "%.0fk", n / 1000.0);
  else
    std::snprintf(buf, sizeof buf, "%zu", n);
  return buf;
}

int runTrain(TrainArgs& a) {
  const auto thread_limit = limitThreads(a.settings.threads);
  a.opt = trainerOptionsFrom(a.settings);
  DatasetOptions dopt;
  dopt.load.downscale = a.downscale;
  if (!a.background.empty()) dopt.background = parseBackground(a.background, "--background");
  const Scene scene = loadDataset(a.dataset, dopt);
  std::cerr << formatWarnings(checkDataset(scene, a.opt.raster.near_plane)) << backgroundWarning(scene);
  const std::vector<int> views = a.views.empty() ? scene.train : parseTrainViews(a.views, scene, "--views");
  fs::create_directories(a.out);
  if (const int n = removeStaleTemporaries(a.out))
    std::cerr << "removed " << n << " temporaries left by a killed run\n";
  const std::string ckpt = a.out + "/checkpoint.bin";
  const std::size_t initial = initialModelSize(scene, a.opt);
  // The views evaluated at the end (the train views where the dataset has no test split).
  const std::vector<int>& eval_views = scene.test.empty() ? scene.train : scene.test;
  const MemoryEstimate memory = estimateTrainingMemory(scene, views, eval_views, initial, a.opt.max_sh_degree);
  const double budget = memoryBudgetBytes(a.memory_budget_gb);
  std::cerr << applyMemoryBudget(memory, budget, a.memory_budget_gb.has_value(), a.opt.densify.max_gaussians);
  Trainer trainer(scene, a.opt);
  if (a.resume && fs::exists(ckpt)) {
    trainer.loadCheckpoint(ckpt);
    if (trainer.iteration() > a.iterations)
      throw InputError(ckpt, "iteration",
                       "the checkpoint is at iteration " + std::to_string(trainer.iteration()) +
                           ", past --iterations " + std::to_string(a.iterations));
    std::cerr << "resumed " << ckpt << " at iteration " << trainer.iteration() << "\n";
  }
  std::cerr << "training on " << views.size() << " views (" << scene.test.size() << " test), "
            << trainer.gaussians().size() << " initial Gaussians, " << a.iterations << " iterations\n";
  trainer.planUntil(a.iterations);
  // Every image this run will read (the training visits each view once per pass when it
  // has at least as many iterations left as views; the evaluation reads the rest), decoded
  // on all cores at once rather than one by one inside the steps.
  {
    std::vector<int> read(eval_views);
    if (a.iterations - trainer.iteration() >= static_cast<int>(views.size()))
      read.insert(read.end(), views.begin(), views.end());
    const auto d0 = std::chrono::steady_clock::now();
    const std::size_t decoded = scene.preloadImages(read);
    std::cerr << "decoded " << decoded << " images in "
              << std::lround(1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - d0).count())
              << " ms\n";
  }
  Progress progress;
  const int start = trainer.iteration();
  const auto t0 = std::chrono::steady_clock::now();
  while (trainer.iteration() < a.iterations) {
    const int chunk =
        std::min(a.iterations - trainer.iteration(),
                 a.checkpoint_every > 0 ? a.checkpoint_every - trainer.iteration() % a.checkpoint_every : a.iterations);
    trainer.train(views, chunk, [&](const TrainProgress& p) {
      char detail[128];
      std::snprintf(detail, sizeof detail, "it %d  loss %.4f  Gaussians %s", p.iteration, p.loss_ema,
                    shortCount(p.gaussians).c_str());
      progress.update("train", p.iteration - start, a.iterations - start, detail);
    });
    if (a.checkpoint_every > 0) trainer.saveCheckpoint(ckpt);
  }
  const double train_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  const Evaluation ev = trainer.evaluate(eval_views, /*keep_renders=*/true);
  writeTestRenders(trainer, ev, a.out + "/test_renders");
  writeGaussiansPly(a.out + "/point_cloud.ply", gaussiansToWorld(trainer.gaussians(), scene.frame));
  writeCamerasJson(a.out + "/cameras.json", scene);  // beside the .ply, for splat viewers

  nlohmann::json j;
  j["dataset"] = a.dataset;
  j["iterations"] = a.iterations;
  j["evaluated_on"] = scene.test.empty() ? "train (the dataset has no test views)" : "test";
  j["psnr"] = ev.psnr;
  j["ssim"] = ev.ssim;
  j["gaussians"] = trainer.gaussians().size();
  j["max_gaussians"] = a.opt.densify.max_gaussians;
  j["settings"] = trainSettingsJson(a.settings);
  j["memory"] = {{"estimate_at_start_bytes", memory.bytesFor(initial)},
                 {"estimate_at_end_bytes", memory.bytesFor(trainer.gaussians().size())},
                 {"budget_bytes", budget},
                 {"budget_from", a.memory_budget_gb ? "--memory-budget" : "available"},
                 {"peak_rss_bytes", peakRssBytes()}};
  j["train_seconds_this_run"] = train_seconds;
  j["threads"] = rasterThreadCount(a.opt.raster.execution);
  j["residual"] = a.opt.residual.enabled;
  j["frame"] = toJson(scene.frame);
  j["background"] = backgroundJson(scene);
  const StageSeconds& s = trainer.seconds();
  j["stage_seconds"] = {{"render", s.render},
                        {"loss", s.loss},
                        {"backward", s.backward},
                        {"optimizer", s.optimizer},
                        {"densify", s.densify}};
  for (const ViewMetrics& m : ev.views)
    j["views"].push_back(
        {{"name", scene.views[static_cast<std::size_t>(m.view)].name}, {"psnr", m.psnr}, {"ssim", m.ssim}});
  writeFileAtomic(a.out + "/results.json", j.dump(2) + "\n");
  std::printf("PSNR %.2f dB  SSIM %.4f  on %zu %s views; %zu Gaussians; %.1f s (%.1f it/s)\n", ev.psnr, ev.ssim,
              ev.views.size(), scene.test.empty() ? "train" : "test", trainer.gaussians().size(), train_seconds,
              train_seconds > 0 ? (a.iterations - start) / train_seconds : 0.0);
  std::printf("wrote %s/results.json, %s/test_renders/, %s/point_cloud.ply\n", a.out.c_str(), a.out.c_str(),
              a.out.c_str());
  return 0;
}

}  // namespace

void addTrainCommand(CLI::App& app, Action& action) {
  auto a = std::make_shared<TrainArgs>();
  CLI::App* sub = app.add_subcommand("train", "Train 3D Gaussians on all train views of a dataset");
  sub->add_option("--dataset", a->dataset, "COLMAP, Blender or `saresgs scene` folder")->required();
  sub->add_option("--out", a->out, "Output folder")->required();
  addRanged(sub, "--iterations", a->iterations, "Training iterations", 1, 10000000);
  addRanged(sub, "--downscale", a->downscale, "Image downscale factor", 1, 64);
  sub->add_option("--background", a->background, kBackgroundHelp)->check(backgroundValue());
  addSettingFlags(sub, a->settings, trainSettingFields());
  sub->add_option("--memory-budget", a->memory_budget_gb,
                  "GB this run may use: refused before it starts if its images and initial model do not fit, the model "
                  "capped to fit (default: refused only beyond what the machine has available)")
      ->check(CLI::Range(0.001, 1e6));
  sub->add_option("--views", a->views,
                  "Train on these train views only, in this order (indices or image names, comma-separated; e.g. an "
                  "active run's selected_views to refit them)");
  sub->add_option("--checkpoint-every", a->checkpoint_every, "Iterations between checkpoints (0: none)")
      ->check(wholeNumberAtLeast(0))
      ->capture_default_str();
  sub->add_flag("--resume", a->resume, "Continue from OUT/checkpoint.bin when it exists");
  sub->callback([&action, a] { action = [a] { return runTrain(*a); }; });
}

}  // namespace saresgs::apps
