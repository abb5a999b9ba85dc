// saresgs bench select: a selection step of path-variance against FisherRF's on one model
// (nbv/eval/selection_bench.h), with the machine and its load named.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "apps/cli_checks.h"
#include "apps/commands.h"
#include "splat/thread_limit.h"
#include "geometry/synth/synthetic_scene.h"
#include "geometry/synth/write_dataset.h"
#include "nbv/eval/selection_bench.h"

namespace saresgs::apps {

namespace {

struct SelectBenchArgs {
  std::string dataset;
  int width = 256, height = 192;
  SelectionBenchOptions opt;
};

std::string firstLine(const char* path, const char* prefix = nullptr) {
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);)
    if (!prefix)
      return line;
    else if (line.rfind(prefix, 0) == 0)
      return line.substr(line.find(':') + 2);
  return "unknown";
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

int runSelectBench(SelectBenchArgs& a) {
  const auto thread_limit = limitThreads(a.opt.threads);
  std::string path = a.dataset;
  if (path.empty()) {
    path = "out/bench_room360_" + std::to_string(a.width) + "x" + std::to_string(a.height);
    if (!std::filesystem::exists(path + "/manifest.json")) {
      SyntheticOptions so;
      so.layout = "room360";
      so.width = a.width;
      so.height = a.height;
      std::cerr << "bench select: writing the room360 scene at " << a.width << "x" << a.height << " to " << path
                << " (once)\n";
      writeSyntheticDataset(makeSyntheticScene(so), path);
    }
  }
  const std::string load_before = firstLine("/proc/loadavg");
  const SelectionBenchResult r = benchSelection(loadDataset(path), a.opt);
  std::vector<double> ratio;
  for (std::size_t k = 0; k < r.fisher_seconds.size(); ++k)
    ratio.push_back(r.path_variance_seconds[k] / r.fisher_seconds[k]);
  nlohmann::json j;
  j["benchmark"] = "select";
  j["dataset"] = path;
  j["held"] = a.opt.held;
  j["candidates"] = r.candidates;
  j["gaussians"] = r.gaussians;
  j["threads"] = a.opt.threads;
  j["fisher_seconds"] = r.fisher_seconds;
  j["path_variance_seconds"] = r.path_variance_seconds;
  j["fisher_median_s"] = median(r.fisher_seconds);
  j["path_variance_median_s"] = median(r.path_variance_seconds);
  j["ratio_per_round"] = ratio;
  j["ratio_median"] = median(ratio);
  j["choices"] = {{"fisher", r.fisher_choice}, {"path-variance", r.path_variance_choice}};
  j["unseen_share"] = {{"median", median(r.unseen_share)},
                       {"max", *std::max_element(r.unseen_share.begin(), r.unseen_share.end())},
                       {"fisher_choice", r.fisher_choice_unseen_share}};
  j["cpu"] = firstLine("/proc/cpuinfo", "model name");
  j["loadavg_before"] = load_before;
  j["loadavg_after"] = firstLine("/proc/loadavg");
  std::cout << j.dump() << std::endl;
  return 0;
}

}  // namespace

void addSelectBenchCommand(CLI::App& bench, Action& action) {
  auto a = std::make_shared<SelectBenchArgs>();
  CLI::App* sub = bench.add_subcommand(
      "select",
      "Time a selection step of path-variance against FisherRF's on the same model, held views and candidates");
  sub->add_option("--dataset", a->dataset,
                  "Dataset folder (default: the built-in room360 scene at --width x --height, written once to out/)");
  sub->add_option("--width", a->width, "Image width of the built-in scene")
      ->check(CLI::Range(16, 8192))
      ->capture_default_str();
  sub->add_option("--height", a->height, "Image height of the built-in scene")
      ->check(CLI::Range(16, 8192))
      ->capture_default_str();
  sub->add_option("--held", a->opt.held, "Views held when the step is taken")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  sub->add_option("--train-iterations", a->opt.train_iterations, "Training on the held views first")
      ->check(CLI::Range(0, 1000000))
      ->capture_default_str();
  sub->add_option("--rounds", a->opt.rounds, "Rounds, each one step of each method")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  sub->add_option("--threads", a->opt.threads, "Threads (0: all cores)")->check(CLI::Range(0, 1024));
  sub->add_option("--seed", a->opt.seed, "Trainer seed")->check(wholeNumberAtLeast(0))->capture_default_str();
  sub->add_option("--kappa", a->opt.kappa, "path-variance's relative damping")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  sub->callback([&action, a] { action = [a] { return runSelectBench(*a); }; });
}

}  // namespace saresgs::apps
