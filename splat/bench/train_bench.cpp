#include "splat/bench/train_bench.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <optional>
#include <vector>

#include "geometry/scene/scene.h"
#include "geometry/synth/synthetic_scene.h"
#include "geometry/synth/write_dataset.h"
#include "splat/bench/step_bench.h"
#include "splat/raster_execution.h"
#include "splat/thread_limit.h"
#include "splat/train/trainer.h"

namespace saresgs {

std::string benchDataset(const std::string& dataset, int width, int height, const char* who) {
  if (!dataset.empty()) return dataset;
  const std::string dir = "out/bench_room360_" + std::to_string(width) + "x" + std::to_string(height);
  if (!std::filesystem::exists(dir + "/manifest.json")) {
    SyntheticOptions so;
    so.layout = "room360";
    so.width = width;
    so.height = height;
    std::cerr << who << ": writing the room360 scene at " << width << "x" << height << " to " << dir << " (once)\n";
    writeSyntheticDataset(makeSyntheticScene(so), dir);
  }
  return dir;
}

nlohmann::json benchTrain(const TrainBenchOptions& o) {
  const std::string load_before = loadAverage();
  const auto thread_limit = limitThreads(o.threads);
  const std::string path = benchDataset(o.dataset, o.width, o.height, "bench train");
  const Scene scene = loadDataset(path);
  TrainerOptions opt;
  opt.seed = o.seed;
  opt.raster.execution.threads = o.threads;
  TrainerOptions plain_opt = opt;
  opt.residual.enabled = o.residual;
  Trainer trainer(scene, opt);
  // With residual: a plain trainer from the same start, timed in alternation.
  std::optional<Trainer> plain;
  if (o.residual) plain.emplace(scene, plain_opt);
  // Decoding the images is paid once per view in a real run; timed apart here.
  auto t0 = std::chrono::steady_clock::now();
  for (int v : scene.train) (void)scene.image(v);
  const double decode_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::size_t gaussians_start = trainer.gaussians().size();
  trainer.train(scene.train, o.warmup);
  if (plain) plain->train(scene.train, o.warmup);
  const StageSeconds s0 = trainer.seconds();
  const StageSeconds p0 = plain ? plain->seconds() : StageSeconds{};
  auto allocations = [&] { return o.heap_allocations ? o.heap_allocations() : 0; };
  const std::uint64_t allocs0 = allocations(), faults0 = pageFaults();
  std::vector<double> it_ms, plain_it_ms;
  double wall = 0, plain_wall = 0;
  // Runs n iterations of t, appending each one's time; returns the chunk's wall seconds.
  auto timeChunk = [&](Trainer& t, int n, std::vector<double>& ms) {
    auto last = std::chrono::steady_clock::now();
    const auto start = last;
    t.train(scene.train, n, [&](const TrainProgress&) {
      const auto now = std::chrono::steady_clock::now();
      ms.push_back(std::chrono::duration<double, std::milli>(now - last).count());
      last = now;
    });
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  constexpr int kChunk = 10;
  for (int done = 0; done < o.iterations;) {
    const int n = plain ? std::min(kChunk, o.iterations - done) : o.iterations;
    wall += timeChunk(trainer, n, it_ms);
    if (plain) plain_wall += timeChunk(*plain, n, plain_it_ms);
    done += n;
  }
  // Allocations and faults per iteration of either trainer (they share the process).
  const int timed = o.iterations * (plain ? 2 : 1);
  const double allocs = static_cast<double>(allocations() - allocs0) / timed;
  const double faults = static_cast<double>(pageFaults() - faults0) / timed;
  // A trainer's stages over the timed iterations, in ms per iteration, and as JSON with
  // what they leave of the mean iteration ("other").
  const double k = 1e3 / o.iterations;
  auto msPerIteration = [&](const StageSeconds& end, const StageSeconds& start) {
    return StageSeconds{(end.render - start.render) * k, (end.loss - start.loss) * k,
                        (end.backward - start.backward) * k, (end.optimizer - start.optimizer) * k,
                        (end.densify - start.densify) * k};
  };
  auto stages = [](const StageSeconds& ms, double per) {
    return nlohmann::json{{"render", ms.render},  {"loss", ms.loss},       {"backward", ms.backward},
                          {"adam", ms.optimizer}, {"densify", ms.densify}, {"other", per - ms.total()}};
  };
  const StageSeconds ms = msPerIteration(trainer.seconds(), s0);
  const double per_it = 1e3 * wall / o.iterations;

  // The trained model's footprint, on the first train view.
  const Camera& cam = scene.views[scene.train.front()].camera;
  const RenderResult r = trainer.render(cam);
  double contrib = 0;
  for (int n : r.contributors) contrib += n;
  contrib /= static_cast<double>(std::max<std::size_t>(1, r.contributors.size()));

  // bench step at the model's size, the view's resolution and the trainer's SH degree.
  StepBenchOptions b;
  b.width = cam.K.width;
  b.height = cam.K.height;
  b.gaussians = static_cast<int>(trainer.gaussians().size());
  b.sh_degree = trainer.activeShDegree();
  b.threads = o.threads;
  b.steps = o.compare_steps;
  b.heap_allocations = o.heap_allocations;
  const StepTimes st = timeBenchSteps(b, o.residual);

  nlohmann::json j;
  j["benchmark"] = "train";
  j["residual"] = o.residual;
  j["dataset"] = path;
  j["width"] = cam.K.width;
  j["height"] = cam.K.height;
  j["train_views"] = scene.train.size();
  j["iterations"] = o.iterations;
  j["warmup_iterations"] = o.warmup;
  j["threads"] = rasterThreadCount(opt.raster.execution);
  j["kernels"] = rasterKernelName(opt.raster.execution);
  j["gaussians_start"] = gaussians_start;
  j["gaussians_end"] = trainer.gaussians().size();
  j["sh_degree_end"] = trainer.activeShDegree();
  j["iterations_per_second"] = o.iterations / wall;
  j["mean_iteration_ms"] = per_it;
  j["median_iteration_ms"] = sampleMedian(it_ms);
  j["stage_ms"] = stages(ms, per_it);
  if (plain) {
    const double plain_per_it = 1e3 * plain_wall / o.iterations;
    j["plain"] = {{"iterations_per_second", o.iterations / plain_wall},
                  {"mean_iteration_ms", plain_per_it},
                  {"median_iteration_ms", sampleMedian(plain_it_ms)},
                  {"gaussians_end", plain->gaussians().size()},
                  {"stage_ms", stages(msPerIteration(plain->seconds(), p0), plain_per_it)}};
    j["residual_to_plain_ratio"] = per_it / plain_per_it;
  }
  j["image_decode_ms_per_view"] = 1e3 * decode_s / static_cast<double>(std::max<std::size_t>(1, scene.train.size()));
  j["mean_contributors_per_pixel"] = contrib;
  if (o.heap_allocations) j["allocations_per_iteration"] = allocs;
  j["page_faults_per_iteration"] = faults;
  nlohmann::json step = {
      {"median_ms", st.median_ms},
      {"mean_contributors_per_pixel", st.mean_contributors},
      {"stage_ms",
       {{"render", st.render_ms}, {"loss", st.loss_ms}, {"backward", st.backward_ms}, {"adam", st.adam_ms}}}};
  if (o.heap_allocations) step["allocations_per_step"] = st.allocations_per_step;
  j["bench_step_same_size"] = step;
  j["train_minus_step_ms"] = {
      {"render", ms.render - st.render_ms}, {"loss", ms.loss - st.loss_ms}, {"backward", ms.backward - st.backward_ms},
      {"adam", ms.optimizer - st.adam_ms},  {"densify", ms.densify},        {"total", per_it - st.median_ms}};
  nameMachine(j, load_before);
  return j;
}

}  // namespace saresgs
