// saresgs bench: benchmarks, each printing one JSON line (timings, the machine and its load,
// peak memory). Not tests: speed is measured here. The harnesses live in the libraries
// (splat/bench/, nbv/eval/); this file parses their flags and prints their line.
//   step       one training step (forward + loss + backward + Adam) on a reproducible
//              random scene;
//   fisher     FisherRF's squared-gradient pass of one view against the backward pass of
//              the same view, same scene and process;
//   train      whole training iterations of a real scene (the built-in room360 by default) by
//              stage, beside `step` at the same size;
//   occupancy  the prefilter's parts on a room360 scene with simulated SfM points;
//   select     a selection step of path-variance against FisherRF's on one model.
#include <nlohmann/json.hpp>

#include <iostream>
#include <memory>

#include "apps/cli_checks.h"
#include "apps/commands.h"
#include "apps/heap_count.h"
#include "nbv/eval/occupancy_bench.h"
#include "nbv/eval/selection_bench.h"
#include "splat/bench/step_bench.h"
#include "splat/bench/train_bench.h"

namespace saresgs::apps {

namespace {

int printLine(const nlohmann::json& j) {
  std::cout << j.dump() << std::endl;
  return 0;
}

void addThreadsAndSeed(CLI::App* sub, int& threads, std::uint64_t& seed, const char* seed_what) {
  sub->add_option("--threads", threads, "Threads (0: all cores)")->check(CLI::Range(0, 1024));
  sub->add_option("--seed", seed, seed_what)->check(wholeNumberAtLeast(0))->capture_default_str();
}

// The random scene's flags, shared by `bench step` and `bench fisher`.
void addRandomSceneFlags(CLI::App* sub, StepBenchOptions& o, const char* timed_what) {
  addRanged(sub, "--width", o.width, "Image width", 1, 16384);
  addRanged(sub, "--height", o.height, "Image height", 1, 16384);
  addRanged(sub, "--gaussians", o.gaussians, "Number of Gaussians", 1, 100000000);
  addRanged(sub, "--sh-degree", o.sh_degree, "SH degree (active)", 0, 3);
  addRanged(sub, "--coverage", o.coverage, "Mean 3-sigma ellipses per pixel", 0.01, 1000.0);
  addRanged(sub, "--steps", o.steps, std::string("Timed ") + timed_what, 1, 100000);
  addRanged(sub, "--warmup", o.warmup, std::string("Untimed ") + timed_what + " first", 0, 100000);
  addThreadsAndSeed(sub, o.threads, o.seed, "Scene seed");
  o.heap_allocations = &heapAllocations;
}

// The built-in scene's size, for the benchmarks that train on a dataset.
void addDatasetFlags(CLI::App* sub, std::string& dataset, int& width, int& height) {
  sub->add_option("--dataset", dataset,
                  "Dataset folder (default: the built-in room360 scene at --width x --height, written once to out/)");
  addRanged(sub, "--width", width, "Image width of the built-in scene", 16, 8192);
  addRanged(sub, "--height", height, "Image height of the built-in scene", 16, 8192);
}

struct SelectBenchArgs {
  std::string dataset;
  int width = 256, height = 192;
  SelectionBenchOptions opt;
};

}  // namespace

void addBenchCommand(CLI::App& app, Action& action) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks (speed is measured here, not in the tests)");
  bench->require_subcommand(1);

  auto s = std::make_shared<StepBenchOptions>();
  CLI::App* step = bench->add_subcommand("step", "Time training steps on a reproducible random scene");
  addRandomSceneFlags(step, *s, "steps");
  step->add_flag("--residual", s->residual, "Time residual-supervision steps too, and their ratio to plain ones");
  step->callback([&action, s] { action = [s] { return printLine(benchStep(*s)); }; });

  auto f = std::make_shared<StepBenchOptions>();
  f->width = 256;
  f->height = 192;
  f->gaussians = 40000;
  CLI::App* fisher = bench->add_subcommand(
      "fisher", "Time the Fisher (squared-gradient) pass against the backward pass of the same view");
  addRandomSceneFlags(fisher, *f, "iterations");
  fisher->callback([&action, f] { action = [f] { return printLine(benchFisher(*f)); }; });

  auto tr = std::make_shared<TrainBenchOptions>();
  tr->heap_allocations = &heapAllocations;
  CLI::App* train = bench->add_subcommand(
      "train", "Time whole training iterations of a real scene by stage, beside `bench step` at the same size");
  addDatasetFlags(train, tr->dataset, tr->width, tr->height);
  addRanged(train, "--iterations", tr->iterations, "Timed iterations", 1, 1000000);
  addRanged(train, "--warmup", tr->warmup, "Untimed iterations first", 0, 1000000);
  addRanged(train, "--compare-steps", tr->compare_steps, "Timed steps of the same-size `bench step`", 1, 100000);
  addThreadsAndSeed(train, tr->threads, tr->seed, "Trainer seed");
  train->add_flag("--residual", tr->residual,
                  "Train with residual supervision, alternated in chunks of 10 iterations with a plain trainer from "
                  "the same start; reports both and their ratio");
  train->callback([&action, tr] { action = [tr] { return printLine(benchTrain(*tr)); }; });

  auto o = std::make_shared<OccupancyBenchOptions>();
  CLI::App* occ = bench->add_subcommand(
      "occupancy", "Time the prefilter's parts (grids, candidate sets, scoring) on a room360 scene");
  addRanged(occ, "--width", o->width, "Image width of the views", 8, 16384);
  addRanged(occ, "--height", o->height, "Image height of the views", 8, 16384);
  addRanged(occ, "--points", o->points, "Simulated SfM points at most", 1, 10000000);
  addRanged(occ, "--resolution", o->resolution, "Coarse voxels along the longest box side", 1, 4096);
  addRanged(occ, "--upsample", o->upsample, "Fine voxels per coarse voxel per axis", 1, 16);
  addRanged(occ, "--min-points", o->min_points, "SfM points for an occupied coarse voxel", 1, 1000000);
  addThreadsAndSeed(occ, o->threads, o->seed, "Scene and SfM seed");
  occ->callback([&action, o] { action = [o] { return printLine(benchOccupancy(*o)); }; });

  auto a = std::make_shared<SelectBenchArgs>();
  CLI::App* sel = bench->add_subcommand(
      "select",
      "Time a selection step of path-variance against FisherRF's on the same model, held views and candidates");
  addDatasetFlags(sel, a->dataset, a->width, a->height);
  addRanged(sel, "--held", a->opt.held, "Views held when the step is taken", 1, 100000);
  addRanged(sel, "--train-iterations", a->opt.train_iterations, "Training on the held views first", 0, 1000000);
  addRanged(sel, "--rounds", a->opt.rounds, "Rounds, each one step of each method", 1, 1000);
  addThreadsAndSeed(sel, a->opt.threads, a->opt.seed, "Trainer seed");
  addRanged(sel, "--kappa", a->opt.kappa, "path-variance's relative damping", 0.0, 1e6);
  sel->callback([&action, a] {
    action = [a] {
      return printLine(benchSelectionJson(benchDataset(a->dataset, a->width, a->height, "bench select"), a->opt));
    };
  });
}

}  // namespace saresgs::apps
