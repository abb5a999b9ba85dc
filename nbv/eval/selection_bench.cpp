#include "nbv/eval/selection_bench.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "nbv/initial_views.h"
#include "nbv/path_variance.h"
#include "nbv/preset.h"
#include "nbv/selectors.h"
#include "splat/bench/machine.h"
#include "splat/fisher.h"
#include "splat/thread_limit.h"
#include "splat/train/trainer.h"

namespace saresgs {

SelectionBenchResult benchSelection(const Scene& scene, const SelectionBenchOptions& opt) {
  if (opt.held < 1 || static_cast<std::size_t>(opt.held) >= scene.train.size())
    throw std::invalid_argument("bench select: --held " + std::to_string(opt.held) +
                                " must be at least 1 and below the " + std::to_string(scene.train.size()) +
                                " train views");
  std::vector<Eigen::Vector3d> centres;
  for (int v : scene.train) centres.push_back(scene.views.at(static_cast<std::size_t>(v)).camera.center());
  std::vector<int> held;
  for (int k : farthestPointSampling(centres, opt.held)) held.push_back(scene.train[static_cast<std::size_t>(k)]);
  std::vector<int> candidates;
  for (int v : scene.train)
    if (std::find(held.begin(), held.end(), v) == held.end()) candidates.push_back(v);

  TrainerOptions to = presetOptions(Preset::kQuick).trainer;
  to.seed = opt.seed;
  to.raster.execution.threads = opt.threads;
  Trainer trainer(scene, to);
  trainer.train(held, opt.train_iterations);
  const Gaussians& g = trainer.gaussians();
  const RasterSettings s = trainer.rasterSettings();
  const double lambda = presetOptions(Preset::kQuick).fisher_lambda;

  SelectionBenchResult r;
  r.candidates = static_cast<int>(candidates.size());
  r.gaussians = g.size();
  using Clock = std::chrono::steady_clock;
  auto seconds = [](Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); };
  for (int round = 0; round < opt.rounds; ++round) {
    // The order alternates: FisherRF first in even rounds, path-variance first in odd ones.
    std::vector<double> f, p;
    for (int k = 0; k < 2; ++k) {
      const auto t0 = Clock::now();
      if ((k == 0) == (round % 2 == 0)) {
        f = fisherScores(g, s, scene, held, candidates, lambda);
        r.fisher_seconds.push_back(seconds(t0));
      } else {
        p = pathVarianceScores(g, s, scene, held, candidates, {lambda, opt.kappa});
        r.path_variance_seconds.push_back(seconds(t0));
      }
    }
    r.fisher_choice = candidates[argmaxScore(f, candidates)];
    r.path_variance_choice = candidates[argmaxScore(p, candidates)];
  }
  Gaussians H = g.zerosLike(), Hc = g.zerosLike();
  for (int v : held) addViewInformation(g, scene.views.at(static_cast<std::size_t>(v)).camera, s, H);
  for (int c : candidates) {
    clearInformation(Hc);
    addViewInformation(g, scene.views.at(static_cast<std::size_t>(c)).camera, s, Hc);
    r.unseen_share.push_back(unseenShare(Hc, H, lambda));
    if (c == r.fisher_choice) r.fisher_choice_unseen_share = r.unseen_share.back();
  }
  return r;
}

nlohmann::json benchSelectionJson(const std::string& path, const SelectionBenchOptions& opt) {
  const std::string load_before = loadAverage();
  const auto thread_limit = limitThreads(opt.threads);
  const SelectionBenchResult r = benchSelection(loadDataset(path), opt);
  std::vector<double> ratio;
  for (std::size_t k = 0; k < r.fisher_seconds.size(); ++k)
    ratio.push_back(r.path_variance_seconds[k] / r.fisher_seconds[k]);
  nlohmann::json j = {{"benchmark", "select"},
                      {"dataset", path},
                      {"held", opt.held},
                      {"candidates", r.candidates},
                      {"gaussians", r.gaussians},
                      {"threads", opt.threads},
                      {"fisher_seconds", r.fisher_seconds},
                      {"path_variance_seconds", r.path_variance_seconds},
                      {"fisher_median_s", sampleMedian(r.fisher_seconds)},
                      {"path_variance_median_s", sampleMedian(r.path_variance_seconds)},
                      {"ratio_per_round", ratio},
                      {"ratio_median", sampleMedian(ratio)}};
  j["choices"] = {{"fisher", r.fisher_choice}, {"path-variance", r.path_variance_choice}};
  j["unseen_share"] = {
      {"median", sampleMedian(r.unseen_share)},
      {"max", r.unseen_share.empty() ? 0.0 : *std::max_element(r.unseen_share.begin(), r.unseen_share.end())},
      {"fisher_choice", r.fisher_choice_unseen_share}};
  nameMachine(j, load_before);
  return j;
}

}  // namespace saresgs
