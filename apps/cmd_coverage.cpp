// saresgs coverage: which voxels do these views observe, and which other views would add
// most? No training: SA-Points come from ground-truth renders when the dataset is a
// rebuildable synthetic scene, from a trained model (--model) otherwise.
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "apps/cli_checks.h"
#include "apps/commands.h"
#include "nbv/prefilter_options.h"
#include "apps/view_list.h"
#include "geometry/scene/dataset_checks.h"
#include "geometry/error.h"
#include "geometry/io/atomic_file.h"
#include "nbv/eval/coverage_report.h"
#include "splat/model_frame.h"
#include "splat/ply.h"

namespace saresgs::apps {

namespace {

struct CoverageArgs {
  std::string dataset, out, views, model;
  PrefilterConfig config;  // numeric options; the textual ones are in `flags`
  PrefilterFlags flags;
  int downscale = 1;
};

int runCoverage(const CoverageArgs& a) {
  const PrefilterConfig config = parsePrefilterFlags(a.flags, a.config, "--");
  DatasetOptions dopt;
  dopt.load.downscale = a.downscale;
  const Scene scene = loadDataset(a.dataset, dopt);
  std::cerr << formatWarnings(checkDataset(scene));
  const std::vector<int> views = parseTrainViews(a.views, scene, "--views");
  Gaussians model;
  if (!a.model.empty()) model = gaussiansFromWorld(readGaussiansPly(a.model), scene.frame);
  const CoverageRenderers renderers =
      coverageRenderers(scene, a.dataset, a.model.empty() ? nullptr : &model, a.model, "--model");
  const std::string& source = renderers.source;
  std::cerr << "coverage of " << views.size() << " views from " << source << "\n";
  const CoverageAnalysis c = analyzeCoverage(scene, views, config, renderers.render, renderers.depth);

  std::filesystem::create_directories(a.out);
  nlohmann::json j;
  j["dataset"] = a.dataset;
  j["source"] = source;
  j["set"] = toString(config.set);
  j["encoding"] = encodingName(config.scoring);
  j["prefilter_regime"] = toJson(c.prefilter->regime());
  j["score"] = toString(config.scoring.criterion);
  j["lifting"] = toString(config.lifting);
  auto name = [&](int v) { return scene.views[static_cast<std::size_t>(v)].name; };
  for (int v : views) j["views"].push_back(name(v));
  j["observed_fraction"] = c.observed_fraction;
  j["scene_voxels"] = c.scene_voxels;
  j["observed_voxels"] = c.observed_voxels;
  j["sa_points"] = c.lifting.toJson();
  for (int v : c.top) j["top"].push_back(name(v));
  j["seconds"] = {{"grid", c.seconds_grid},
                  {"lifting", c.seconds_lifting},
                  {"triangulation", c.seconds_triangulation},
                  {"scoring", c.seconds_scoring}};
  std::string csv = "view,score,rank,kept\n";
  for (const auto& k : c.candidates) {
    j["candidates"].push_back({{"view", name(k.view)}, {"score", k.score}, {"rank", k.rank}, {"kept", k.kept}});
    csv +=
        name(k.view) + "," + std::to_string(k.score) + "," + std::to_string(k.rank) + "," + (k.kept ? "1" : "0") + "\n";
  }
  writeFileAtomic(a.out + "/coverage.json", j.dump(2) + "\n");
  writeFileAtomic(a.out + "/coverage.csv", csv);
  writeImage(a.out + "/coverage.png", plotCoverage(scene, c));

  std::printf("observed %zu of %zu scene voxels (%.1f %%) from %zu SA-Points; kept %zu of %zu candidates\n",
              c.observed_voxels, c.scene_voxels, 100 * c.observed_fraction, c.lifting.kept, c.top.size(),
              c.candidates.size());
  std::printf("%-16s %12s %6s\n", "candidate",
              config.scoring.criterion == CoverageCriterion::NewCount ? "new voxels" : "hamming", "rank");
  std::vector<CandidateCoverage> by_rank = c.candidates;
  std::sort(by_rank.begin(), by_rank.end(), [](const auto& x, const auto& y) { return x.rank < y.rank; });
  for (std::size_t i = 0; i < by_rank.size() && i < 10; ++i)
    std::printf("%-16s %12.6g %6d%s\n", name(by_rank[i].view).c_str(), by_rank[i].score, by_rank[i].rank,
                by_rank[i].kept ? "  *" : "");
  std::printf("seconds: grid %.3f, lifting %.2f, triangulation %.3f, scoring %.3f\n", c.seconds_grid, c.seconds_lifting,
              c.seconds_triangulation, c.seconds_scoring);
  std::printf("wrote %s/coverage.json, coverage.csv, coverage.png\n", a.out.c_str());
  return 0;
}

}  // namespace

void addCoverageCommand(CLI::App& app, Action& action) {
  auto a = std::make_shared<CoverageArgs>();
  CLI::App* sub = app.add_subcommand("coverage", "Observed voxels of some views and the coverage score of the others");
  sub->add_option("--dataset", a->dataset, "COLMAP, Blender or `saresgs scene` folder")->required();
  sub->add_option("--views", a->views,
                  "Observed train views: indices into the train list or image names, comma-separated")
      ->required();
  sub->add_option("--out", a->out, "Output folder")->required();
  sub->add_option("--model", a->model, "Trained .ply to render extrapolated views (datasets without ground truth)");
  sub->add_option("--set", a->flags.set, "frustum | visible")->capture_default_str();
  a->flags.scene = "";  // --resolution and --min-points are this command's own flags
  sub->add_option("--encoding", a->flags.encoding,
                  "hash:auto (the smallest 2^K, K = 11..19, with load <= 0.5) | hash:K (K = 11..19) | exact")
      ->capture_default_str();
  sub->add_option("--score", a->flags.score, "xor | new")->capture_default_str();
  sub->add_option("--lifting", a->flags.lifting, "flow | depth | oracle (the dataset's ground-truth depth maps)")
      ->capture_default_str();
  addRanged(sub, "--keep", a->config.keep_fraction, "Fraction of candidates kept (top N %)", 0.0, 1.0);
  addRanged(sub, "--resolution", a->config.resolution, "Grid resolution along the longest side", 4, 4096);
  addRanged(sub, "--min-points", a->config.min_points, "SfM points per occupied voxel (paper: 2 outdoor, 5 indoor)", 1,
            1000);
  addRanged(sub, "--upsample", a->config.upsample, "Upsampling of the occupied voxels", 1, 16);
  addRanged(sub, "--stride", a->config.visible_stride, "Pixel stride of visibility rays", 1, 64);
  addRanged(sub, "--downscale", a->downscale, "Image downscale factor", 1, 64);
  sub->callback([&action, a] { action = [a] { return runCoverage(*a); }; });
}

}  // namespace saresgs::apps
