// saresgs bench: benchmarks, each printing one JSON line (timings, machine, peak memory).
// Not tests: speed is measured here.
//   step       one training step (forward + loss + backward + Adam) on a reproducible
//              random scene;
//   fisher     FisherRF's squared-gradient pass of one view against the backward pass of
//              the same view, same scene and process (the ratio is what the Fisher
//              selector costs per candidate relative to a training backward);
//   train      whole training iterations of a real scene (the built-in room360 by default) by
//              stage, beside `step` at the same size: where a real iteration's time goes;
//   occupancy  the prefilter's parts on a room360 scene with simulated SfM points: grid
//              build, observed dilation, frustum vs visible sets, exact vs hashed scoring,
//              grid memory.
#include <nlohmann/json.hpp>
#include <sys/resource.h>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <optional>
#include <random>

#include "apps/cli_checks.h"
#include "apps/commands.h"
#include "splat/thread_limit.h"
#include "apps/heap_count.h"
#include "apps/memory_budget.h"
#include "geometry/error.h"
#include "geometry/occupancy/candidate_sets.h"
#include "geometry/occupancy/coverage_score.h"
#include "geometry/occupancy/occupancy_grid.h"
#include "geometry/synth/simulated_sfm.h"
#include "geometry/synth/synthetic_scene.h"
#include "geometry/synth/write_dataset.h"
#include "geometry/scene/scene.h"
#include "splat/fisher.h"
#include "splat/loss.h"
#include "splat/raster_execution.h"
#include "splat/train/trainer.h"

namespace saresgs::apps {

namespace {

struct BenchArgs {
  int width = 512, height = 384;
  int gaussians = 20000;
  int sh_degree = 3;
  double coverage = 16;
  int warmup = 3, steps = 21;
  int threads = 0;
  bool residual = false;
  std::uint64_t seed = 1;
};

Camera benchCamera(const BenchArgs& a) {
  Intrinsics K;
  K.width = a.width;
  K.height = a.height;
  K.fx = K.fy = 0.85 * a.width;
  K.cx = 0.5 * a.width;
  K.cy = 0.5 * a.height;
  return Camera::lookAt(K, Eigen::Vector3d(0, 0, -5), Eigen::Vector3d(0, 0, 0), -Eigen::Vector3d::UnitY());
}

// Gaussians filling the view frustum between depths 3 and 7 with random anisotropic
// scales, rotations, opacities and SH. The scale is set so that, on average, `coverage`
// Gaussians' 3-sigma ellipses overlap a pixel: a trained model's density, not a fixed
// world size, so that the 20k and 100k scenes stay comparable.
Gaussians benchScene(const BenchArgs& a, std::uint64_t seed, const Camera& cam) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> nd(0, 1);
  Gaussians g;
  g.max_sh_degree = a.sh_degree;
  g.resize(static_cast<std::size_t>(a.gaussians));
  const int K = g.shCoeffs();
  const double sigma_px = std::sqrt(a.coverage * a.width * a.height / (a.gaussians * M_PI * 9.0));
  const Eigen::Matrix3d Rt = cam.R.transpose();
  for (int i = 0; i < a.gaussians; ++i) {
    const double z = 5 + 2 * u(rng);
    const Eigen::Vector3d pc(u(rng) * 0.5 * a.width / cam.K.fx * z, u(rng) * 0.5 * a.height / cam.K.fy * z, z);
    const Eigen::Vector3d pw = Rt * (pc - cam.t);
    const double s = sigma_px * z / cam.K.fx;
    for (int k = 0; k < 3; ++k) {
      g.means[3 * i + k] = static_cast<float>(pw[k]);
      g.log_scales[3 * i + k] = static_cast<float>(std::log(s) + 0.4 * nd(rng));
    }
    for (int k = 0; k < 4; ++k) g.rotations[4 * i + k] = static_cast<float>(nd(rng));
    g.opacities[i] = static_cast<float>(nd(rng));
    for (int k = 0; k < 3 * K; ++k) g.sh[3 * K * i + k] = static_cast<float>((k < 3 ? 1.0 : 0.2) * nd(rng));
  }
  return g;
}

std::string cpuName() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown";
}

double peakRssMb() { return peakRssBytes() / (1024.0 * 1024.0); }

struct StepTimes {
  double median_ms = 0;
  StageSeconds stages;  // summed over the timed steps
  double mean_contributors = 0;
  double allocations_per_step = 0;  // C++ heap allocations (apps/heap_count.h), timed steps
  double page_faults_per_step = 0;  // minor + major, whole process, timed steps
};

// Page faults (minor + major) of the whole process so far.
std::uint64_t pageFaults() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return static_cast<std::uint64_t>(ru.ru_minflt + ru.ru_majflt);
}

StepTimes timeSteps(const BenchArgs& a, const Camera& cam, const ImageF& target, bool residual) {
  Gaussians g = benchScene(a, a.seed, cam);
  AdamState adam;
  adam.resetFor(g);
  Gaussians grad = g.zerosLike();
  std::vector<float> grad2d;
  StepBuffers buffers;
  RasterSettings s;
  s.sh_degree = a.sh_degree;
  s.execution.threads = a.threads;
  ResidualOptions res;
  res.enabled = residual;
  std::mt19937_64 rng(a.seed);
  LearningRates lr;
  std::vector<double> ms;
  ms.reserve(static_cast<std::size_t>(a.steps));  // not counted as the steps' allocations
  StepTimes out;
  std::uint64_t allocs0 = 0, faults0 = 0;
  for (int it = 0; it < a.warmup + a.steps; ++it) {
    if (it == a.warmup) allocs0 = heapAllocations(), faults0 = pageFaults();
    StageSeconds secs;
    const auto t0 = std::chrono::steady_clock::now();
    // grad is zero: the last step's Adam cleared it, as the trainer's does.
    grad2d.assign(2 * g.size(), 0.0f);
    viewLossAndGradient(g, cam, s, target, 0.2, res, rng, grad, grad2d, secs, buffers);
    const auto t1 = std::chrono::steady_clock::now();
    adamStepClearingGradient(g, grad, adam, lr);
    const auto t2 = std::chrono::steady_clock::now();
    secs.optimizer = std::chrono::duration<double>(t2 - t1).count();
    if (it >= a.warmup) {
      ms.push_back(1e3 * std::chrono::duration<double>(t2 - t0).count());
      out.stages.render += secs.render;
      out.stages.loss += secs.loss;
      out.stages.backward += secs.backward;
      out.stages.optimizer += secs.optimizer;
    }
  }
  out.allocations_per_step = static_cast<double>(heapAllocations() - allocs0) / a.steps;
  out.page_faults_per_step = static_cast<double>(pageFaults() - faults0) / a.steps;
  std::sort(ms.begin(), ms.end());
  out.median_ms = ms[ms.size() / 2];
  const RenderResult r = rasterize(g, cam, s);
  double c = 0;
  for (int n : r.contributors) c += n;
  out.mean_contributors = c / static_cast<double>(r.contributors.size());
  return out;
}

nlohmann::json stageJson(const StageSeconds& s, int steps) {
  const double k = 1e3 / steps;
  return {{"render", s.render * k}, {"loss", s.loss * k}, {"backward", s.backward * k}, {"adam", s.optimizer * k}};
}

// Refuses, before allocating, a scene the machine cannot hold: about 1.2 kB per Gaussian
// (parameters, gradients, Adam moments, projections, tile pairs at this coverage) and
// 200 B per pixel (images, per-pixel state, loss buffers), against half the memory.
void checkBenchSize(const BenchArgs& a) {
  const double need = 1200.0 * a.gaussians * std::max(1.0, a.coverage / 16) + 200.0 * a.width * a.height;
  const double have = static_cast<double>(::sysconf(_SC_PHYS_PAGES)) * static_cast<double>(::sysconf(_SC_PAGE_SIZE));
  if (have > 0 && need > 0.5 * have) {
    char msg[256];
    std::snprintf(msg, sizeof msg,
                  "needs about %.1f GB for %lld Gaussians at %dx%d; the limit is half this machine's memory, %.1f GB",
                  need / 1e9, static_cast<long long>(a.gaussians), a.width, a.height, 0.5 * have / 1e9);
    throw InputError("--gaussians/--width/--height", "size", msg);
  }
}

int runBench(const BenchArgs& a) {
  const auto thread_limit = limitThreads(a.threads);
  checkBenchSize(a);
  const Camera cam = benchCamera(a);
  RasterSettings s;
  s.sh_degree = a.sh_degree;
  s.execution.threads = a.threads;
  // The target is another random scene's render: gradients of a realistic size.
  const ImageF target = rasterize(benchScene(a, a.seed + 1000, cam), cam, s).rgb;
  const StepTimes plain = timeSteps(a, cam, target, false);
  nlohmann::json j;
  j["benchmark"] = "step";
  j["width"] = a.width;
  j["height"] = a.height;
  j["gaussians"] = a.gaussians;
  j["sh_degree"] = a.sh_degree;
  j["coverage"] = a.coverage;
  j["mean_contributors_per_pixel"] = plain.mean_contributors;
  j["threads"] = rasterThreadCount(s.execution);
  j["kernels"] = rasterKernelName(s.execution);
  j["steps"] = a.steps;
  j["residual"] = a.residual;
  if (a.residual) {
    const StepTimes res = timeSteps(a, cam, target, true);
    j["median_ms"] = res.median_ms;
    j["plain_median_ms"] = plain.median_ms;
    j["residual_to_plain_ratio"] = res.median_ms / plain.median_ms;
    j["stage_ms"] = stageJson(res.stages, a.steps);
    j["plain_stage_ms"] = stageJson(plain.stages, a.steps);
    j["residual_allocations_per_step"] = res.allocations_per_step;
  } else {
    j["median_ms"] = plain.median_ms;
    j["stage_ms"] = stageJson(plain.stages, a.steps);
  }
  // How far from the floor: contributing Gaussian-pixel pairs per step, each pass's ns per
  // pair and core, and the forward arithmetic's own cost on one core with no memory
  // traffic (rasterForwardFloorNsPerPair). The kernels also evaluate pixels no Gaussian
  // reaches within its rectangle, so the fraction is a lower bound on their efficiency.
  {
    const double pairs = plain.mean_contributors * a.width * a.height;
    const int threads = rasterThreadCount(s.execution);
    const double k = 1e6 * threads / (pairs * a.steps);
    const double floor_ns = rasterForwardFloorNsPerPair(s.execution);
    const double render_ns = plain.stages.render * 1e3 * k, backward_ns = plain.stages.backward * 1e3 * k;
    j["pairs_per_step"] = pairs;
    j["ns_per_pair_core"] = {{"render", render_ns}, {"backward", backward_ns}};
    j["floor_ns_per_pair"] = floor_ns;
    j["render_fraction_of_floor"] = floor_ns / render_ns;
  }
  j["allocations_per_step"] = plain.allocations_per_step;
  j["page_faults_per_step"] = plain.page_faults_per_step;
  j["peak_rss_mb"] = peakRssMb();
  j["cpu"] = cpuName();
  std::cout << j.dump() << std::endl;
  return 0;
}

// The Fisher pass (rasterizeSquaredGradients given a forward render), the full
// addViewInformation (forward + Fisher pass) and the backward pass of the same view, each
// timed per iteration in the same loop so that load changes hit all three alike.
int runFisherBench(const BenchArgs& a) {
  const auto thread_limit = limitThreads(a.threads);
  checkBenchSize(a);
  const Camera cam = benchCamera(a);
  RasterSettings s;
  s.sh_degree = a.sh_degree;
  s.execution.threads = a.threads;
  const Gaussians g = benchScene(a, a.seed, cam);
  // dL/drgb as in training: the photometric loss against another random scene's render.
  const ImageF target = rasterize(benchScene(a, a.seed + 1000, cam), cam, s).rgb;
  const RenderResult fwd = rasterize(g, cam, s);
  const ImageF dL = photometricLoss(fwd.rgb, target, 0.2, true).grad;
  Gaussians H = g.zerosLike(), grad = g.zerosLike();
  std::vector<double> fisher_ms, view_ms, backward_ms, forward_ms;
  auto ms = [](auto t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  };
  for (int it = 0; it < a.warmup + a.steps; ++it) {
    const bool timed = it >= a.warmup;
    auto t0 = std::chrono::steady_clock::now();
    const RenderResult r = rasterize(g, cam, s);
    if (timed) forward_ms.push_back(ms(t0));
    clearInformation(H);
    t0 = std::chrono::steady_clock::now();
    rasterizeSquaredGradients(g, cam, s, r, H);
    if (timed) fisher_ms.push_back(ms(t0));
    clearInformation(grad);
    t0 = std::chrono::steady_clock::now();
    rasterizeBackward(g, cam, s, r, dL, grad);
    if (timed) backward_ms.push_back(ms(t0));
    clearInformation(H);
    t0 = std::chrono::steady_clock::now();
    addViewInformation(g, cam, s, H);
    if (timed) view_ms.push_back(ms(t0));
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  double c = 0;
  for (int n : fwd.contributors) c += n;
  // A checksum of the information, so that runs (and thread counts) can be compared.
  double checksum = 0;
  H.forEachArray([&](const std::vector<float>& x, std::size_t) {
    for (float v : x) checksum += v;
  });
  nlohmann::json j;
  j["benchmark"] = "fisher";
  j["width"] = a.width;
  j["height"] = a.height;
  j["gaussians"] = a.gaussians;
  j["sh_degree"] = a.sh_degree;
  j["coverage"] = a.coverage;
  j["mean_contributors_per_pixel"] = c / static_cast<double>(fwd.contributors.size());
  j["threads"] = rasterThreadCount(s.execution);
  j["kernels"] = rasterKernelName(s.execution);
  j["steps"] = a.steps;
  j["fisher_ms"] = median(fisher_ms);
  j["view_information_ms"] = median(view_ms);
  j["forward_ms"] = median(forward_ms);
  j["backward_ms"] = median(backward_ms);
  j["fisher_to_backward_ratio"] = median(fisher_ms) / median(backward_ms);
  j["information_sum"] = checksum;
  j["peak_rss_mb"] = peakRssMb();
  j["cpu"] = cpuName();
  std::cout << j.dump() << std::endl;
  return 0;
}

struct TrainBenchArgs {
  std::string dataset;  // empty: the built-in room360 scene at width x height
  int width = 512, height = 384;
  int iterations = 300;
  int warmup = 10;
  int threads = 0;
  int compare_steps = 21;
  std::uint64_t seed = 0;
  // Residual supervision (the main job's training): times it against a plain trainer from
  // the same start, the two alternated in chunks so that the machine's drift hits both.
  bool residual = false;
};

// The dataset to train on: the given folder, or the built-in room360 scene at the
// requested size, written once to out/bench_room360_WxH (reused by later runs).
std::string trainBenchDataset(const TrainBenchArgs& a) {
  if (!a.dataset.empty()) return a.dataset;
  const std::string dir = "out/bench_room360_" + std::to_string(a.width) + "x" + std::to_string(a.height);
  if (!std::filesystem::exists(dir + "/manifest.json")) {
    SyntheticOptions so;
    so.layout = "room360";
    so.width = a.width;
    so.height = a.height;
    std::cerr << "bench train: writing the room360 scene at " << a.width << "x" << a.height << " to " << dir
              << " (once)\n";
    writeSyntheticDataset(makeSyntheticScene(so), dir);
  }
  return dir;
}

// Whole training iterations of a real scene (what `saresgs train` pays), by the trainer's
// own stages, next to `bench step` on a random scene of the same size, resolution, SH
// degree and threads in the same process: the difference says where a real iteration's
// extra time goes (the model's footprint per pixel, densification statistics, image
// decoding, bookkeeping).
int runTrainBench(const TrainBenchArgs& a) {
  const auto thread_limit = limitThreads(a.threads);
  const std::string path = trainBenchDataset(a);
  const Scene scene = loadDataset(path);
  TrainerOptions opt;
  opt.seed = a.seed;
  opt.raster.execution.threads = a.threads;
  TrainerOptions plain_opt = opt;
  opt.residual.enabled = a.residual;
  Trainer trainer(scene, opt);
  // With --residual: a plain trainer from the same start, timed in alternation.
  std::optional<Trainer> plain;
  if (a.residual) plain.emplace(scene, plain_opt);
  // Decoding the images is paid once per view in a real run; timed apart here.
  auto t0 = std::chrono::steady_clock::now();
  for (int v : scene.train) (void)scene.image(v);
  const double decode_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::size_t gaussians_start = trainer.gaussians().size();
  trainer.train(scene.train, a.warmup);
  if (plain) plain->train(scene.train, a.warmup);
  const StageSeconds s0 = trainer.seconds();
  const StageSeconds p0 = plain ? plain->seconds() : StageSeconds{};
  const std::uint64_t allocs0 = heapAllocations(), faults0 = pageFaults();
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
  for (int done = 0; done < a.iterations;) {
    const int n = plain ? std::min(kChunk, a.iterations - done) : a.iterations;
    wall += timeChunk(trainer, n, it_ms);
    if (plain) plain_wall += timeChunk(*plain, n, plain_it_ms);
    done += n;
  }
  // Allocations and faults per iteration of either trainer (they share the process).
  const int timed = a.iterations * (plain ? 2 : 1);
  const double allocs = static_cast<double>(heapAllocations() - allocs0) / timed;
  const double faults = static_cast<double>(pageFaults() - faults0) / timed;
  // A trainer's stages over the timed iterations, in ms per iteration, and as JSON with
  // what they leave of the mean iteration ("other").
  const double k = 1e3 / a.iterations;
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
  const double per_it = 1e3 * wall / a.iterations;
  std::sort(it_ms.begin(), it_ms.end());
  std::sort(plain_it_ms.begin(), plain_it_ms.end());

  // The trained model's footprint, on the first train view.
  const Camera& cam = scene.views[scene.train.front()].camera;
  const RenderResult r = trainer.render(cam);
  double contrib = 0;
  for (int n : r.contributors) contrib += n;
  contrib /= static_cast<double>(std::max<std::size_t>(1, r.contributors.size()));

  // bench step at the model's size, the view's resolution and the trainer's SH degree.
  BenchArgs b;
  b.width = cam.K.width;
  b.height = cam.K.height;
  b.gaussians = static_cast<int>(trainer.gaussians().size());
  b.sh_degree = trainer.activeShDegree();
  b.threads = a.threads;
  b.steps = a.compare_steps;
  const Camera bcam = benchCamera(b);
  RasterSettings rs;
  rs.sh_degree = b.sh_degree;
  rs.execution.threads = b.threads;
  const ImageF target = rasterize(benchScene(b, b.seed + 1000, bcam), bcam, rs).rgb;
  const StepTimes st = timeSteps(b, bcam, target, a.residual);
  const double sk = 1e3 / b.steps;

  nlohmann::json j;
  j["benchmark"] = "train";
  j["residual"] = a.residual;
  j["dataset"] = path;
  j["width"] = cam.K.width;
  j["height"] = cam.K.height;
  j["train_views"] = scene.train.size();
  j["iterations"] = a.iterations;
  j["warmup_iterations"] = a.warmup;
  j["threads"] = rasterThreadCount(opt.raster.execution);
  j["kernels"] = rasterKernelName(opt.raster.execution);
  j["gaussians_start"] = gaussians_start;
  j["gaussians_end"] = trainer.gaussians().size();
  j["sh_degree_end"] = trainer.activeShDegree();
  j["iterations_per_second"] = a.iterations / wall;
  j["mean_iteration_ms"] = per_it;
  j["median_iteration_ms"] = it_ms[it_ms.size() / 2];
  j["stage_ms"] = stages(ms, per_it);
  if (plain) {
    const double plain_per_it = 1e3 * plain_wall / a.iterations;
    j["plain"] = {{"iterations_per_second", a.iterations / plain_wall},
                  {"mean_iteration_ms", plain_per_it},
                  {"median_iteration_ms", plain_it_ms[plain_it_ms.size() / 2]},
                  {"gaussians_end", plain->gaussians().size()},
                  {"stage_ms", stages(msPerIteration(plain->seconds(), p0), plain_per_it)}};
    j["residual_to_plain_ratio"] = per_it / plain_per_it;
  }
  j["image_decode_ms_per_view"] = 1e3 * decode_s / static_cast<double>(std::max<std::size_t>(1, scene.train.size()));
  j["mean_contributors_per_pixel"] = contrib;
  j["allocations_per_iteration"] = allocs;
  j["page_faults_per_iteration"] = faults;
  j["bench_step_same_size"] = {{"median_ms", st.median_ms},
                               {"mean_contributors_per_pixel", st.mean_contributors},
                               {"stage_ms", stageJson(st.stages, b.steps)},
                               {"allocations_per_step", st.allocations_per_step}};
  j["train_minus_step_ms"] = {{"render", ms.render - st.stages.render * sk},
                              {"loss", ms.loss - st.stages.loss * sk},
                              {"backward", ms.backward - st.stages.backward * sk},
                              {"adam", ms.optimizer - st.stages.optimizer * sk},
                              {"densify", ms.densify},
                              {"total", per_it - st.median_ms}};
  j["peak_rss_mb"] = peakRssMb();
  j["cpu"] = cpuName();
  std::cout << j.dump() << std::endl;
  return 0;
}

struct OccupancyBenchArgs {
  int width = 256, height = 192;  // the synthetic views (their depth maps give SA-Points)
  std::size_t points = 12000;     // simulated SfM points at most
  int resolution = 128;           // coarse voxels along the box's longest side
  int upsample = 2;
  int min_points = 2;
  int threads = 0;
  std::uint64_t seed = 5;
};

double medianMs(int reps, const std::function<void()>& f) {
  std::vector<double> t;
  for (int i = 0; i < reps; ++i) {
    const auto a = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

int runOccupancyBench(const OccupancyBenchArgs& a) {
  const auto thread_limit = limitThreads(a.threads);
  const int threads =
      std::min<int>(tbb::info::default_concurrency(),
                    static_cast<int>(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)));

  // A room360 scene and what COLMAP would give for it.
  SyntheticOptions so;
  so.layout = "room360";
  so.width = a.width;
  so.height = a.height;
  so.seed = a.seed;
  const SyntheticScene scene = makeSyntheticScene(so);
  ColmapModel model = colmapModelOf(scene);
  SimulatedSfmOptions sim;
  sim.max_points = a.points;
  sim.candidates = 4 * a.points;
  sim.seed = a.seed;
  simulateSfm(scene, model, sim);
  std::vector<Eigen::Vector3d> sfm;
  for (const auto& [id, p] : model.points) sfm.push_back(p.xyz);
  const std::vector<Camera>& cams = scene.cameras;

  OccupancyOptions o;
  o.resolution = a.resolution;
  o.min_points = a.min_points;
  o.upsample = a.upsample;
  std::optional<OccupancyGrids> g;
  const double t_build = medianMs(7, [&] { g.emplace(OccupancyGrids::fromSfm(sfm, o)); });
  // Observed: depth-map points of 8 train views spread over the split (stand-ins for
  // SA-Points), every second pixel.
  std::vector<Eigen::Vector3d> sa;
  const std::size_t views = std::min<std::size_t>(8, scene.train.size());
  for (std::size_t k = 0; k < views; ++k) {
    const Camera& cam = cams[scene.train[k * scene.train.size() / views]];
    const ImageF depth = scene.renderDepth(cam);
    for (int v = 0; v < depth.height; v += 2)
      for (int u = 0; u < depth.width; u += 2)
        if (depth.at(u, v) > 0) sa.push_back(cam.unproject(Eigen::Vector2d(u + 0.5, v + 0.5), depth.at(u, v)));
  }
  const double t_obs = medianMs(5, [&] {
    g->clearObserved();
    g->addObserved(sa);
  });
  const VoxelSet obs = g->observedSceneVoxels();
  std::optional<VisibilityTracer> tracer;
  const double t_tracer = medianMs(3, [&] { tracer.emplace(*g); });

  // Per candidate: every camera of the scene is a candidate.
  const double n = static_cast<double>(cams.size());
  std::vector<VoxelSet> fr(cams.size()), vis(cams.size());
  const double t_fr = medianMs(3,
                               [&] {
                                 for (std::size_t j = 0; j < cams.size(); ++j) fr[j] = frustumSet(*g, cams[j]);
                               }) /
                      n;
  const double t_vis4 = medianMs(3,
                                 [&] {
                                   for (std::size_t j = 0; j < cams.size(); ++j)
                                     vis[j] = tracer->visibleSet(cams[j], 4);
                                 }) /
                        n;
  const double t_vis1 = medianMs(1,
                                 [&] {
                                   for (std::size_t j = 0; j < cams.size(); ++j) tracer->visibleSet(cams[j], 1);
                                 }) /
                        n;
  double mean_fr = 0, mean_vis = 0;
  for (std::size_t j = 0; j < cams.size(); ++j) {
    mean_fr += static_cast<double>(fr[j].size());
    mean_vis += static_cast<double>(vis[j].size());
  }

  CoverageScoring p;
  p.encoding = CoverageEncoding::Exact;
  const double t_exact = medianMs(5, [&] { scoreCandidates(obs, fr, g->sceneCount(), p); }) / n;
  p.encoding = CoverageEncoding::Hashed;
  p.table_size = std::size_t{1} << 19;
  const double t_h19 = medianMs(5, [&] { scoreCandidates(obs, fr, g->sceneCount(), p); }) / n;
  p.table_size = std::size_t{1} << 11;
  const double t_h11 = medianMs(5, [&] { scoreCandidates(obs, fr, g->sceneCount(), p); }) / n;
  // The dense path, on one thread: encode each candidate into T bits, XOR/popcount all T.
  const HashedBits ho = HashedBits::encode(obs, std::size_t{1} << 19);
  const double t_dense19 = medianMs(5,
                                    [&] {
                                      for (const VoxelSet& c : fr)
                                        scoreHashed(ho, HashedBits::encode(c, std::size_t{1} << 19));
                                    }) /
                           n;
  const GridMemory m = g->memory();

  nlohmann::json j;
  j["benchmark"] = "occupancy";
  j["layout"] = "room360";
  j["width"] = a.width;
  j["height"] = a.height;
  j["sfm_points"] = sfm.size();
  j["cameras"] = cams.size();
  j["resolution"] = a.resolution;
  j["upsample"] = a.upsample;
  j["min_points"] = a.min_points;
  j["threads"] = threads;
  j["coarse_voxels"] = g->coarseCount();
  j["scene_voxels"] = g->sceneCount();
  j["voxel_size"] = g->voxelSize();
  j["observed_points"] = sa.size();
  j["observed_voxels"] = g->observedCount();
  j["observed_scene_voxels"] = obs.size();
  j["observed_fraction"] = g->observedFraction();
  j["mean_frustum_voxels"] = mean_fr / n;
  j["mean_visible_voxels"] = mean_vis / n;
  j["stage_ms"] = {{"scene_grid", t_build}, {"add_observed", t_obs}, {"embree_bvh", t_tracer}};
  j["per_candidate_ms"] = {{"frustum_set", t_fr},
                           {"visible_set_stride4", t_vis4},
                           {"visible_set_stride1", t_vis1},
                           {"score_exact", t_exact},
                           {"score_hashed_2pow19", t_h19},
                           {"score_hashed_2pow11", t_h11},
                           {"score_dense_2pow19_1thread", t_dense19}};
  j["memory_kb"] = {{"scene_vdb", m.scene_vdb / 1024.0},
                    {"observed_vdb", m.observed_vdb / 1024.0},
                    {"scene_index", m.scene_index / 1024.0}};
  j["peak_rss_mb"] = peakRssMb();
  j["cpu"] = cpuName();
  std::cout << j.dump() << std::endl;
  return 0;
}

}  // namespace

void addBenchCommand(CLI::App& app, Action& action) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks (speed is measured here, not in the tests)");
  bench->require_subcommand(1);
  auto a = std::make_shared<BenchArgs>();
  CLI::App* step = bench->add_subcommand("step", "Time training steps on a reproducible random scene");
  step->add_option("--width", a->width, "Image width")->check(CLI::Range(1, 16384))->capture_default_str();
  step->add_option("--height", a->height, "Image height")->check(CLI::Range(1, 16384))->capture_default_str();
  step->add_option("--gaussians", a->gaussians, "Number of Gaussians")
      ->check(CLI::Range(1, 100000000))
      ->capture_default_str();
  step->add_option("--sh-degree", a->sh_degree, "SH degree (active)")->check(CLI::Range(0, 3))->capture_default_str();
  step->add_option("--coverage", a->coverage, "Mean 3-sigma ellipses per pixel")
      ->check(CLI::Range(0.01, 1000.0))
      ->capture_default_str();
  step->add_option("--steps", a->steps, "Timed steps")->check(CLI::Range(1, 100000))->capture_default_str();
  step->add_option("--warmup", a->warmup, "Untimed steps first")->check(CLI::Range(0, 100000))->capture_default_str();
  step->add_option("--threads", a->threads, "Threads (0: all cores)")->check(CLI::Range(0, 1024));
  step->add_option("--seed", a->seed, "Scene seed")->check(wholeNumberAtLeast(0))->capture_default_str();
  step->add_flag("--residual", a->residual, "Time residual-supervision steps too, and their ratio to plain ones");
  step->callback([&action, a] { action = [a] { return runBench(*a); }; });

  auto f = std::make_shared<BenchArgs>();
  f->width = 256;
  f->height = 192;
  f->gaussians = 40000;
  CLI::App* fisher = bench->add_subcommand(
      "fisher", "Time the Fisher (squared-gradient) pass against the backward pass of the same view");
  fisher->add_option("--width", f->width, "Image width")->check(CLI::Range(1, 16384))->capture_default_str();
  fisher->add_option("--height", f->height, "Image height")->check(CLI::Range(1, 16384))->capture_default_str();
  fisher->add_option("--gaussians", f->gaussians, "Number of Gaussians")
      ->check(CLI::Range(1, 100000000))
      ->capture_default_str();
  fisher->add_option("--sh-degree", f->sh_degree, "SH degree (active)")->check(CLI::Range(0, 3))->capture_default_str();
  fisher->add_option("--coverage", f->coverage, "Mean 3-sigma ellipses per pixel")
      ->check(CLI::Range(0.01, 1000.0))
      ->capture_default_str();
  fisher->add_option("--steps", f->steps, "Timed iterations")->check(CLI::Range(1, 100000))->capture_default_str();
  fisher->add_option("--warmup", f->warmup, "Untimed iterations first")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  fisher->add_option("--threads", f->threads, "Threads (0: all cores)")->check(CLI::Range(0, 1024));
  fisher->add_option("--seed", f->seed, "Scene seed")->check(wholeNumberAtLeast(0))->capture_default_str();
  fisher->callback([&action, f] { action = [f] { return runFisherBench(*f); }; });

  auto tr = std::make_shared<TrainBenchArgs>();
  CLI::App* train = bench->add_subcommand(
      "train", "Time whole training iterations of a real scene by stage, beside `bench step` at the same size");
  train->add_option("--dataset", tr->dataset,
                    "Dataset folder (default: the built-in room360 scene at --width x --height, written once to out/)");
  train->add_option("--width", tr->width, "Image width of the built-in scene")
      ->check(CLI::Range(16, 8192))
      ->capture_default_str();
  train->add_option("--height", tr->height, "Image height of the built-in scene")
      ->check(CLI::Range(16, 8192))
      ->capture_default_str();
  train->add_option("--iterations", tr->iterations, "Timed iterations")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  train->add_option("--warmup", tr->warmup, "Untimed iterations first")
      ->check(CLI::Range(0, 1000000))
      ->capture_default_str();
  train->add_option("--compare-steps", tr->compare_steps, "Timed steps of the same-size `bench step`")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  train->add_option("--threads", tr->threads, "Threads (0: all cores)")->check(CLI::Range(0, 1024));
  train->add_option("--seed", tr->seed, "Trainer seed")->check(wholeNumberAtLeast(0))->capture_default_str();
  train->add_flag("--residual", tr->residual,
                  "Train with residual supervision, alternated in chunks of 10 iterations with a plain trainer from "
                  "the same start; reports both and their ratio");
  train->callback([&action, tr] { action = [tr] { return runTrainBench(*tr); }; });

  auto o = std::make_shared<OccupancyBenchArgs>();
  CLI::App* occ = bench->add_subcommand(
      "occupancy", "Time the prefilter's parts (grids, candidate sets, scoring) on a room360 scene");
  occ->add_option("--width", o->width, "Image width of the views")->check(CLI::Range(8, 16384))->capture_default_str();
  occ->add_option("--height", o->height, "Image height of the views")
      ->check(CLI::Range(8, 16384))
      ->capture_default_str();
  occ->add_option("--points", o->points, "Simulated SfM points at most")
      ->check(CLI::Range(1, 10000000))
      ->capture_default_str();
  occ->add_option("--resolution", o->resolution, "Coarse voxels along the longest box side")
      ->check(CLI::Range(1, 4096))
      ->capture_default_str();
  occ->add_option("--upsample", o->upsample, "Fine voxels per coarse voxel per axis")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  occ->add_option("--min-points", o->min_points, "SfM points for an occupied coarse voxel")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  occ->add_option("--threads", o->threads, "Threads (0: all cores)")->check(CLI::Range(0, 1024));
  occ->add_option("--seed", o->seed, "Scene and SfM seed")->check(wholeNumberAtLeast(0))->capture_default_str();
  occ->callback([&action, o] { action = [o] { return runOccupancyBench(*o); }; });
  addSelectBenchCommand(*bench, action);
}

}  // namespace saresgs::apps
