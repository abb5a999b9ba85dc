#pragma once
// The rasterizer's benchmarks on a reproducible random scene (`saresgs bench step`,
// `saresgs bench fisher`): each returns one JSON line of timings with the machine and its
// load named (splat/bench/machine.h). Speed is measured here, never in the tests.
#include <nlohmann/json_fwd.hpp>

#include <cstdint>

#include "geometry/camera/camera.h"
#include "splat/bench/machine.h"
#include "splat/gaussians.h"

namespace saresgs {

struct StepBenchOptions {
  int width = 512, height = 384;
  int gaussians = 20000;
  int sh_degree = 3;
  double coverage = 16;  // mean 3-sigma ellipses per pixel
  int warmup = 3, steps = 21;
  int threads = 0;        // 0: every core; else caps every TBB pool of the process while it runs
  bool residual = false;  // step: time residual-supervision steps too, and their ratio to plain ones
  std::uint64_t seed = 1;
  HeapAllocationCounter heap_allocations = nullptr;
};

// The camera of the random scene: looking down +z from (0, 0, -5), fx = fy = 0.85 width.
Camera benchCamera(const StepBenchOptions& o);

// Gaussians filling the view frustum between depths 3 and 7 with random anisotropic
// scales, rotations, opacities and SH, scaled so that on average `coverage` Gaussians'
// 3-sigma ellipses overlap a pixel: a trained model's density, not a fixed world size.
Gaussians benchScene(const StepBenchOptions& o, std::uint64_t seed, const Camera& cam);

// Throws InputError naming --gaussians/--width/--height, before allocating, when the
// scene would need more than half this machine's memory.
void checkBenchSize(const StepBenchOptions& o);

// One training step (forward + loss + backward + Adam): the median, the stages, the
// contributing pairs against the forward arithmetic's floor, allocations and page faults
// per step; with `residual`, residual steps beside plain ones and their ratio.
nlohmann::json benchStep(const StepBenchOptions& o);

// FisherRF's squared-gradient pass of one view, the whole addViewInformation and the
// backward pass of the same view, timed in the same loop; with the information's sum as
// a checksum that runs and thread counts can compare.
nlohmann::json benchFisher(const StepBenchOptions& o);

// The medians and stages of `steps` timed training steps (after `warmup`) at o's size,
// against `target`: what `bench train` puts beside a real iteration.
struct StepTimes {
  double median_ms = 0;
  double render_ms = 0, loss_ms = 0, backward_ms = 0, adam_ms = 0;  // per step
  double mean_contributors = 0;
  double allocations_per_step = 0;  // 0 without a heap counter
  double page_faults_per_step = 0;
};
StepTimes timeBenchSteps(const StepBenchOptions& o, bool residual);

}  // namespace saresgs
