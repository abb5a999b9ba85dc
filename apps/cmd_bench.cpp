// saresgs bench step: the time of one training step (forward + loss + backward + Adam)
// on a reproducible random scene, as one JSON line. Not a test: speed is measured here.
#include <nlohmann/json.hpp>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <random>

#include "apps/commands.h"
#include "splat/rasterize_detail.h"
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

struct StepTimes {
  double median_ms = 0;
  StageSeconds stages;  // summed over the timed steps
  double mean_contributors = 0;
};

StepTimes timeSteps(const BenchArgs& a, const Camera& cam, const ImageF& target, bool residual) {
  Gaussians g = benchScene(a, a.seed, cam);
  AdamState adam;
  adam.resetFor(g);
  Gaussians grad = g.zerosLike();
  std::vector<float> grad2d;
  RasterSettings s;
  s.sh_degree = a.sh_degree;
  ResidualOptions res;
  res.enabled = residual;
  std::mt19937_64 rng(a.seed);
  LearningRates lr;
  std::vector<double> ms;
  StepTimes out;
  for (int it = 0; it < a.warmup + a.steps; ++it) {
    StageSeconds secs;
    const auto t0 = std::chrono::steady_clock::now();
    grad.forEachArray([](std::vector<float>& x, std::size_t) { std::fill(x.begin(), x.end(), 0.0f); });
    grad2d.assign(2 * g.size(), 0.0f);
    viewLossAndGradient(g, cam, s, target, 0.2, res, rng, grad, grad2d, secs);
    const auto t1 = std::chrono::steady_clock::now();
    adamStep(g, grad, adam, lr);
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

int runBench(const BenchArgs& a) {
  if (a.threads > 0) setRasterThreads(a.threads);
  const Camera cam = benchCamera(a);
  RasterSettings s;
  s.sh_degree = a.sh_degree;
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
  j["threads"] = rasterThreads();
  j["steps"] = a.steps;
  j["residual"] = a.residual;
  if (a.residual) {
    const StepTimes res = timeSteps(a, cam, target, true);
    j["median_ms"] = res.median_ms;
    j["plain_median_ms"] = plain.median_ms;
    j["residual_to_plain_ratio"] = res.median_ms / plain.median_ms;
    j["stage_ms"] = stageJson(res.stages, a.steps);
    j["plain_stage_ms"] = stageJson(plain.stages, a.steps);
  } else {
    j["median_ms"] = plain.median_ms;
    j["stage_ms"] = stageJson(plain.stages, a.steps);
  }
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  j["peak_rss_mb"] = ru.ru_maxrss / 1024.0;
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
  step->add_option("--gaussians", a->gaussians, "Number of Gaussians")->check(CLI::Range(1, 100000000))->capture_default_str();
  step->add_option("--sh-degree", a->sh_degree, "SH degree (active)")->check(CLI::Range(0, 3))->capture_default_str();
  step->add_option("--coverage", a->coverage, "Mean 3-sigma ellipses per pixel")->check(CLI::Range(0.01, 1000.0))->capture_default_str();
  step->add_option("--steps", a->steps, "Timed steps")->check(CLI::Range(1, 100000))->capture_default_str();
  step->add_option("--warmup", a->warmup, "Untimed steps first")->check(CLI::Range(0, 100000))->capture_default_str();
  step->add_option("--threads", a->threads, "Threads (0: all cores)")->check(CLI::Range(0, 1024));
  step->add_option("--seed", a->seed, "Scene seed")->capture_default_str();
  step->add_flag("--residual", a->residual, "Time residual-supervision steps too, and their ratio to plain ones");
  step->callback([&action, a] { action = [a] { return runBench(*a); }; });
}

}  // namespace saresgs::apps
