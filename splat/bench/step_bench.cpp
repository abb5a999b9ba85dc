#include "splat/bench/step_bench.h"

#include <nlohmann/json.hpp>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "geometry/error.h"
#include "splat/fisher.h"
#include "splat/loss.h"
#include "splat/raster_execution.h"
#include "splat/thread_limit.h"
#include "splat/train/trainer.h"

namespace saresgs {

namespace {

RasterSettings benchSettings(const StepBenchOptions& o) {
  RasterSettings s;
  s.sh_degree = o.sh_degree;
  s.execution.threads = o.threads;
  return s;
}

std::uint64_t allocationsNow(const StepBenchOptions& o) { return o.heap_allocations ? o.heap_allocations() : 0; }

double meanContributors(const RenderResult& r) {
  double c = 0;
  for (int n : r.contributors) c += n;
  return c / static_cast<double>(r.contributors.size());
}

nlohmann::json stageJson(const StepTimes& t) {
  return {{"render", t.render_ms}, {"loss", t.loss_ms}, {"backward", t.backward_ms}, {"adam", t.adam_ms}};
}

// The target of a step is another random scene's render: gradients of a realistic size.
ImageF benchTarget(const StepBenchOptions& o, const Camera& cam) {
  return rasterize(benchScene(o, o.seed + 1000, cam), cam, benchSettings(o)).rgb;
}

StepTimes timeSteps(const StepBenchOptions& o, const Camera& cam, const ImageF& target, bool residual) {
  Gaussians g = benchScene(o, o.seed, cam);
  AdamState adam;
  adam.resetFor(g);
  Gaussians grad = g.zerosLike();
  std::vector<float> grad2d;
  StepBuffers buffers;
  const RasterSettings s = benchSettings(o);
  ResidualOptions res;
  res.enabled = residual;
  std::mt19937_64 rng(o.seed);
  LearningRates lr;
  std::vector<double> ms;
  ms.reserve(static_cast<std::size_t>(o.steps));  // not counted as the steps' allocations
  StageSeconds sum;
  std::uint64_t allocs0 = 0, faults0 = 0;
  for (int it = 0; it < o.warmup + o.steps; ++it) {
    if (it == o.warmup) allocs0 = allocationsNow(o), faults0 = pageFaults();
    StageSeconds secs;
    const auto t0 = std::chrono::steady_clock::now();
    // grad is zero: the last step's Adam cleared it, as the trainer's does.
    grad2d.assign(2 * g.size(), 0.0f);
    viewLossAndGradient(g, cam, s, target, 0.2, res, rng, grad, grad2d, secs, buffers);
    const auto t1 = std::chrono::steady_clock::now();
    adamStepClearingGradient(g, grad, adam, lr);
    const auto t2 = std::chrono::steady_clock::now();
    secs.optimizer = std::chrono::duration<double>(t2 - t1).count();
    if (it >= o.warmup) {
      ms.push_back(1e3 * std::chrono::duration<double>(t2 - t0).count());
      sum.render += secs.render;
      sum.loss += secs.loss;
      sum.backward += secs.backward;
      sum.optimizer += secs.optimizer;
    }
  }
  StepTimes out;
  out.allocations_per_step = static_cast<double>(allocationsNow(o) - allocs0) / o.steps;
  out.page_faults_per_step = static_cast<double>(pageFaults() - faults0) / o.steps;
  out.median_ms = sampleMedian(std::move(ms));
  const double k = 1e3 / o.steps;
  out.render_ms = sum.render * k;
  out.loss_ms = sum.loss * k;
  out.backward_ms = sum.backward * k;
  out.adam_ms = sum.optimizer * k;
  out.mean_contributors = meanContributors(rasterize(g, cam, s));
  return out;
}

// The size of the random scene and its renders: the same keys in both benchmarks.
void describeScene(nlohmann::json& j, const StepBenchOptions& o, const RasterSettings& s) {
  j.update({{"width", o.width},
            {"height", o.height},
            {"gaussians", o.gaussians},
            {"sh_degree", o.sh_degree},
            {"coverage", o.coverage},
            {"threads", rasterThreadCount(s.execution)},
            {"kernels", rasterKernelName(s.execution)},
            {"steps", o.steps}});
}

// What both benchmarks of the random scene start with: the load before, the thread cap,
// the size check (before anything large is allocated), the camera and the settings.
struct RandomSceneBench {
  explicit RandomSceneBench(const StepBenchOptions& o)
      : thread_limit(limitThreads(o.threads)), cam(benchCamera(o)), s(benchSettings(o)) {
    checkBenchSize(o);
  }
  std::string load_before = loadAverage();
  std::unique_ptr<tbb::global_control> thread_limit;
  Camera cam;
  RasterSettings s;
};

}  // namespace

Camera benchCamera(const StepBenchOptions& o) {
  Intrinsics K;
  K.width = o.width;
  K.height = o.height;
  K.fx = K.fy = 0.85 * o.width;
  K.cx = 0.5 * o.width;
  K.cy = 0.5 * o.height;
  return Camera::lookAt(K, Eigen::Vector3d(0, 0, -5), Eigen::Vector3d(0, 0, 0), -Eigen::Vector3d::UnitY());
}

Gaussians benchScene(const StepBenchOptions& o, std::uint64_t seed, const Camera& cam) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> nd(0, 1);
  Gaussians g;
  g.max_sh_degree = o.sh_degree;
  g.resize(static_cast<std::size_t>(o.gaussians));
  const int K = g.shCoeffs();
  const double sigma_px = std::sqrt(o.coverage * o.width * o.height / (o.gaussians * M_PI * 9.0));
  const Eigen::Matrix3d Rt = cam.R.transpose();
  for (int i = 0; i < o.gaussians; ++i) {
    const double z = 5 + 2 * u(rng);
    const Eigen::Vector3d pc(u(rng) * 0.5 * o.width / cam.K.fx * z, u(rng) * 0.5 * o.height / cam.K.fy * z, z);
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

// About 1.2 kB per Gaussian (parameters, gradients, Adam moments, projections, tile pairs
// at this coverage) and 200 B per pixel (images, per-pixel state, loss buffers).
void checkBenchSize(const StepBenchOptions& o) {
  const double need = 1200.0 * o.gaussians * std::max(1.0, o.coverage / 16) + 200.0 * o.width * o.height;
  const double have = static_cast<double>(::sysconf(_SC_PHYS_PAGES)) * static_cast<double>(::sysconf(_SC_PAGE_SIZE));
  if (have > 0 && need > 0.5 * have) {
    char msg[256];
    std::snprintf(msg, sizeof msg,
                  "needs about %.1f GB for %lld Gaussians at %dx%d; the limit is half this machine's memory, %.1f GB",
                  need / 1e9, static_cast<long long>(o.gaussians), o.width, o.height, 0.5 * have / 1e9);
    throw InputError("--gaussians/--width/--height", "size", msg);
  }
}

StepTimes timeBenchSteps(const StepBenchOptions& o, bool residual) {
  const Camera cam = benchCamera(o);
  return timeSteps(o, cam, benchTarget(o, cam), residual);
}

nlohmann::json benchStep(const StepBenchOptions& o) {
  const RandomSceneBench b(o);
  const Camera& cam = b.cam;
  const RasterSettings& s = b.s;
  const ImageF target = benchTarget(o, cam);
  const StepTimes plain = timeSteps(o, cam, target, false);
  nlohmann::json j;
  j["benchmark"] = "step";
  describeScene(j, o, s);
  j["mean_contributors_per_pixel"] = plain.mean_contributors;
  j["residual"] = o.residual;
  if (o.residual) {
    const StepTimes res = timeSteps(o, cam, target, true);
    j["median_ms"] = res.median_ms;
    j["plain_median_ms"] = plain.median_ms;
    j["residual_to_plain_ratio"] = res.median_ms / plain.median_ms;
    j["stage_ms"] = stageJson(res);
    j["plain_stage_ms"] = stageJson(plain);
    j["residual_allocations_per_step"] = res.allocations_per_step;
  } else {
    j["median_ms"] = plain.median_ms;
    j["stage_ms"] = stageJson(plain);
  }
  // How far from the floor: contributing Gaussian-pixel pairs per step, each pass's ns per
  // pair and core, and the forward arithmetic's own cost on one core with no memory
  // traffic (rasterForwardFloorNsPerPair). The kernels also evaluate pixels no Gaussian
  // reaches within its rectangle, so the fraction is a lower bound on their efficiency.
  const double pairs = plain.mean_contributors * o.width * o.height;
  const int threads = rasterThreadCount(s.execution);
  const double k = 1e3 * threads / pairs;  // ms per step -> ns per pair and core
  const double floor_ns = rasterForwardFloorNsPerPair(s.execution);
  const double render_ns = plain.render_ms * k, backward_ns = plain.backward_ms * k;
  j["pairs_per_step"] = pairs;
  j["ns_per_pair_core"] = {{"render", render_ns}, {"backward", backward_ns}};
  j["floor_ns_per_pair"] = floor_ns;
  j["render_fraction_of_floor"] = floor_ns / render_ns;
  if (o.heap_allocations) j["allocations_per_step"] = plain.allocations_per_step;
  j["page_faults_per_step"] = plain.page_faults_per_step;
  nameMachine(j, b.load_before);
  return j;
}

nlohmann::json benchFisher(const StepBenchOptions& o) {
  const RandomSceneBench b(o);
  const Camera& cam = b.cam;
  const RasterSettings& s = b.s;
  const Gaussians g = benchScene(o, o.seed, cam);
  // dL/drgb as in training: the photometric loss against another random scene's render.
  const RenderResult fwd = rasterize(g, cam, s);
  const ImageF dL = photometricLoss(fwd.rgb, benchTarget(o, cam), 0.2, true).grad;
  Gaussians H = g.zerosLike(), grad = g.zerosLike();
  std::vector<double> fisher_ms, view_ms, backward_ms, forward_ms;
  auto ms = [](auto t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  };
  for (int it = 0; it < o.warmup + o.steps; ++it) {
    const bool timed = it >= o.warmup;
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
  double checksum = 0;
  H.forEachArray([&](const std::vector<float>& x, std::size_t) {
    for (float v : x) checksum += v;
  });
  nlohmann::json j;
  j["benchmark"] = "fisher";
  describeScene(j, o, s);
  j["mean_contributors_per_pixel"] = meanContributors(fwd);
  j["fisher_ms"] = sampleMedian(fisher_ms);
  j["view_information_ms"] = sampleMedian(view_ms);
  j["forward_ms"] = sampleMedian(forward_ms);
  j["backward_ms"] = sampleMedian(backward_ms);
  j["fisher_to_backward_ratio"] = sampleMedian(fisher_ms) / sampleMedian(backward_ms);
  j["information_sum"] = checksum;
  nameMachine(j, b.load_before);
  return j;
}

}  // namespace saresgs
