// saresgs active: one active reconstruction run (the product's main job).
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>

#include "apps/commands.h"
#include "apps/progress.h"
#include "geometry/io/atomic_file.h"
#include "nbv/active_run.h"
#include "nbv/camera_plot.h"
#include "splat/ply.h"
#include "splat/rasterize_detail.h"
#include "splat/train/test_renders.h"

namespace saresgs::apps {

namespace {

namespace fs = std::filesystem;

struct ActiveArgs {
  std::string dataset, out, method = "sa-resgs", preset = "quick", fvs_metric = "euclidean", ranking;
  int downscale = 1, threads = 0;
  bool resume = false;
  int max_views = 0, interval = 0, total = 0;
  long long max_gaussians = -1;
  double beta = -1;
  bool sub_only = false;
  ActiveOptions opt;
};

int runActive(ActiveArgs& a) {
  if (a.threads > 0) setRasterThreads(a.threads);
  applyPreset(a.preset, a.opt);
  a.opt.method = parseMethod(a.method);
  a.opt.fvs_metric = a.fvs_metric == "great-circle" ? ViewDistance::kGreatCircle : ViewDistance::kEuclidean;
  if (a.max_views > 0) a.opt.max_views = a.max_views;
  if (a.interval > 0) a.opt.interval = a.interval;
  if (a.total > 0) a.opt.total_iterations = a.total;
  if (a.max_gaussians >= 0) a.opt.trainer.densify.max_gaussians = static_cast<std::size_t>(a.max_gaussians);
  if (a.beta >= 0) a.opt.trainer.residual.beta = a.beta;
  if (!a.ranking.empty()) a.opt.trainer.residual.ranking = parseUncertaintyRanking(a.ranking);
  if (a.sub_only) a.opt.trainer.residual.sub_only = true;
  DatasetOptions dopt;
  dopt.load.downscale = a.downscale;
  const Scene scene = loadDataset(a.dataset, dopt);
  fs::create_directories(a.out);
  const std::string ckpt = a.out + "/checkpoint.json";
  if (!a.resume && fs::exists(ckpt))
    throw std::runtime_error(ckpt + " exists: pass --resume to continue that run, or choose another --out");
  ActiveRun run(scene, a.opt, ckpt);
  std::cerr << "active run: " << a.method << " on " << a.dataset << " (" << scene.train.size() << " candidates, "
            << scene.test.size() << " test views), preset " << a.preset << ", seed " << a.opt.seed << "\n";
  Progress progress;
  const ActiveResult r = run.run([&](const ActiveProgress& p) {
    char detail[160];
    std::snprintf(detail, sizeof detail, "views %d/%d  loss %.4f  PSNR %.2f  Gaussians %zu", p.views, p.max_views,
                  p.loss, p.psnr, p.gaussians);
    progress.update("active", p.iteration, p.total_iterations, detail);
  });
  const Trainer& t = run.trainer();
  writeTestRenders(t, r.test, a.out + "/test_renders");
  writeGaussiansPly(a.out + "/point_cloud.ply", t.gaussians());
  writeImage(a.out + "/cameras.png", plotCameras(scene, r.initial_views, r.selected_views));

  nlohmann::json j;
  j["dataset"] = a.dataset;
  j["method"] = a.method;
  j["seed"] = a.opt.seed;
  j["preset"] = a.preset;
  const ResidualOptions& ro = a.opt.trainer.residual;
  j["options"] = {{"interval", a.opt.interval},
                  {"total_iterations", a.opt.total_iterations},
                  {"max_views", a.opt.max_views},
                  {"max_gaussians", a.opt.trainer.densify.max_gaussians},
                  {"reset_after_add", a.opt.reset_after_add},
                  {"residual", needsOf(a.opt.method).residual},
                  {"residual_alpha", ro.alpha},
                  {"residual_beta", ro.beta},
                  {"residual_ranking", toString(ro.ranking)},
                  {"residual_sub_only", ro.sub_only},
                  {"prefilter_set", a.opt.prefilter.set},
                  {"prefilter_encoding", a.opt.prefilter.encoding},
                  {"prefilter_score", a.opt.prefilter.score},
                  {"prefilter_keep", a.opt.prefilter.keep_fraction}};
  j["psnr"] = r.test.psnr;
  j["ssim"] = r.test.ssim;
  j["ause"] = r.ause ? nlohmann::json(*r.ause) : nlohmann::json(nullptr);
  auto names = [&](const std::vector<int>& v) {
    std::vector<std::string> n;
    for (int i : v) n.push_back(scene.views[static_cast<std::size_t>(i)].name);
    return n;
  };
  j["initial_views"] = names(r.initial_views);
  j["selected_views"] = names(std::vector<int>(r.selected_views.begin() + static_cast<long>(r.initial_views.size()),
                                               r.selected_views.end()));
  j["selected_view_indices"] = r.selected_views;
  j["seconds"] = toJson(r.total_seconds);
  j["seconds"]["end_to_end_this_process"] = r.seconds;
  j["gaussians"] = t.gaussians().size();
  j["iterations"] = r.iterations;
  j["threads"] = rasterThreads();
  for (const ViewMetrics& m : r.test.views)
    j["views"].push_back({{"name", scene.views[static_cast<std::size_t>(m.view)].name}, {"psnr", m.psnr}, {"ssim", m.ssim}});
  for (const SelectionLog& s : r.steps) {
    nlohmann::json e = {{"views_before", s.views_before}, {"progress_psnr", s.progress_psnr}, {"seconds", toJson(s.seconds)}};
    if (s.selected >= 0) {
      e["selected"] = scene.views[static_cast<std::size_t>(s.selected)].name;
      e["candidates"] = names(s.candidates);
      e["scores"] = s.scores;
      if (!s.prefiltered.empty()) e["prefiltered"] = names(s.prefiltered);
    }
    j["steps"].push_back(e);
  }
  writeFileAtomic(a.out + "/results.json", j.dump(2) + "\n");
  std::printf("\n%-10s %-8s %8s %8s %8s %10s %10s %10s\n", "method", "views", "PSNR", "SSIM", "AUSE", "select s", "train s", "total s");
  const double select_s = r.total_seconds.selection();
  std::printf("%-10s %-8zu %8.2f %8.4f %8s %10.1f %10.1f %10.1f\n", a.method.c_str(), r.selected_views.size(), r.test.psnr,
              r.test.ssim, r.ause ? std::to_string(*r.ause).substr(0, 6).c_str() : "n/a", select_s, r.total_seconds.training,
              r.seconds);
  std::printf("wrote %s/results.json, cameras.png, test_renders/, point_cloud.ply\n", a.out.c_str());
  return 0;
}

}  // namespace

void addActiveCommand(CLI::App& app, Action& action) {
  auto a = std::make_shared<ActiveArgs>();
  CLI::App* sub = app.add_subcommand("active", "Active reconstruction: select views one by one while training");
  sub->add_option("--dataset", a->dataset, "COLMAP, Blender or `saresgs scene` folder")->required();
  sub->add_option("--out", a->out, "Output folder")->required();
  sub->add_option("--method", a->method, "random | fvs | fisher | coverage | sa-hash | sa-resgs | resgs")
      ->check(CLI::IsMember({"random", "fvs", "fisher", "coverage", "sa-hash", "sa-resgs", "resgs"}))->capture_default_str();
  sub->add_option("--seed", a->opt.seed, "Random seed")->capture_default_str();
  sub->add_option("--preset", a->preset, "quick | paper")->check(CLI::IsMember({"quick", "paper"}))->capture_default_str();
  sub->add_option("--max-views", a->max_views, "Views at the end (default 20)");
  sub->add_option("--interval", a->interval, "Iterations per view held (preset's by default)");
  sub->add_option("--iterations", a->total, "Total iterations (preset's by default)");
  sub->add_option("--max-gaussians", a->max_gaussians, "Cap on the model size (0: none; preset's by default)");
  sub->add_option("--residual-beta", a->beta, "Uncertain fraction of the residual subset (default 0.1)")->check(CLI::Range(0.0, 1.0));
  sub->add_option("--residual-ranking", a->ranking, "Uncertainty ranking: both | opacity | scale | random (default both)")
      ->check(CLI::IsMember({"both", "opacity", "scale", "random"}));
  sub->add_flag("--residual-sub-only", a->sub_only, "Ablation: subset loss only, no full-render loss");
  sub->add_flag("--continue-training", [a](std::int64_t) { a->opt.reset_after_add = false; },
                "Keep training the same model after each addition instead of resetting it");
  sub->add_option("--fvs-metric", a->fvs_metric, "euclidean | great-circle")
      ->check(CLI::IsMember({"euclidean", "great-circle"}))->capture_default_str();
  sub->add_option("--fisher-lambda", a->opt.fisher_lambda, "Fisher damping")->capture_default_str();
  sub->add_option("--prefilter-set", a->opt.prefilter.set, "frustum | visible")
      ->check(CLI::IsMember({"frustum", "visible"}))->capture_default_str();
  sub->add_option("--prefilter-encoding", a->opt.prefilter.encoding, "hash:K (11..19) | exact")->capture_default_str();
  sub->add_option("--prefilter-score", a->opt.prefilter.score, "xor | new")->check(CLI::IsMember({"xor", "new"}))->capture_default_str();
  sub->add_option("--prefilter-keep", a->opt.prefilter.keep_fraction, "Fraction kept for Fisher")->check(CLI::Range(0.0, 1.0))->capture_default_str();
  sub->add_flag("--time-exhaustive-fisher", a->opt.time_exhaustive_fisher, "Also time Fisher over all candidates");
  sub->add_option("--downscale", a->downscale, "Image downscale factor")->check(CLI::Range(1, 64))->capture_default_str();
  sub->add_option("--threads", a->threads, "Threads (0: all cores)")->check(CLI::Range(0, 1024));
  sub->add_flag("--resume", a->resume, "Continue the run in OUT from its checkpoint");
  sub->callback([&action, a] { action = [a] { return runActive(*a); }; });
}

}  // namespace saresgs::apps
