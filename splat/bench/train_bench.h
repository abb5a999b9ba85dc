#pragma once
// Whole training iterations of a real scene (`saresgs bench train`), by the trainer's own
// stages, beside `bench step` on a random scene of the same size, resolution, SH degree and
// threads in the same process: the difference says where a real iteration's extra time
// goes (the model's footprint per pixel, densification statistics, image decoding,
// bookkeeping). One JSON line, with the machine and its load named.
#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <string>

#include "splat/bench/machine.h"

namespace saresgs {

struct TrainBenchOptions {
  std::string dataset;  // empty: the built-in room360 scene at width x height (benchDataset)
  int width = 512, height = 384;
  int iterations = 300;
  int warmup = 10;
  int threads = 0;  // 0: every core; else caps every TBB pool of the process while it runs
  int compare_steps = 21;
  std::uint64_t seed = 0;
  // Residual supervision (the main job's training): timed against a plain trainer from the
  // same start, the two alternated in chunks of 10 iterations so that drift hits both.
  bool residual = false;
  HeapAllocationCounter heap_allocations = nullptr;
};

// The dataset a benchmark runs on: `dataset` when given, else the built-in room360 scene
// at width x height, written once to out/bench_room360_WxH and reused by later runs
// (`who` names the benchmark in the one line that says it is being written).
std::string benchDataset(const std::string& dataset, int width, int height, const char* who);

nlohmann::json benchTrain(const TrainBenchOptions& o);

}  // namespace saresgs
