// The rasterizer's execution settings resolved: arenas per thread count, kernels per CPU.
#include "splat/raster/execution.h"

#include <chrono>
#include <cstdlib>
#include <algorithm>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>

#include "splat/raster/raster_kernels.h"

namespace saresgs {

namespace raster_execution {

tbb::task_arena& arena(int threads) {
  static std::mutex mutex;
  static std::map<int, std::unique_ptr<tbb::task_arena>> arenas;
  const int want = threads > 0 ? threads : 0;
  std::lock_guard<std::mutex> lock(mutex);
  std::unique_ptr<tbb::task_arena>& a = arenas[want];
  if (!a) a = std::make_unique<tbb::task_arena>(want > 0 ? want : static_cast<int>(tbb::task_arena::automatic));
  return *a;
}

namespace {

// The index of `kernels` among baseline (0), avx2 (1) and avx512 (2).
int kernelIndex(RasterKernels kernels) {
  switch (kernels) {
    case RasterKernels::kBaseline:
      return 0;
    case RasterKernels::kAvx2:
      if (!rasterCpuHasAvx2())
        throw std::invalid_argument("raster kernels avx2: this CPU or build has no AVX2 and FMA");
      return 1;
    case RasterKernels::kAvx512:
      if (!rasterCpuHasAvx512())
        throw std::invalid_argument("raster kernels avx512: this CPU or build has no AVX-512F and AVX-512VL");
      return 2;
    case RasterKernels::kDefault:
      break;
  }
  // The best kernels this CPU runs, unless SARESGS_RASTER_ISA names others ("baseline",
  // "avx2", "avx512" or "default"): read at the first render, like the process's other
  // defaults. A name this CPU cannot run, or no kernels' name, throws, and is read again
  // at the next render.
  static const int index = [] {
    const char* env = std::getenv("SARESGS_RASTER_ISA");
    const std::optional<RasterKernels> k = env ? parseRasterKernels(env) : RasterKernels::kDefault;
    if (!k)
      throw std::invalid_argument(std::string("environment SARESGS_RASTER_ISA='") + env +
                                  "': expected baseline, avx2, avx512 or default");
    if (*k == RasterKernels::kDefault) return rasterCpuHasAvx512() ? 2 : rasterCpuHasAvx2() ? 1 : 0;
    try {
      return kernelIndex(*k);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("environment SARESGS_RASTER_ISA: ") + e.what());
    }
  }();
  return index;
}

// AVX2's kernel set with the walks compiled for AVX-512VL (raster_kernels_avx512.cpp), or
// null when this build lacks either.
const raster_kernels::KernelSet* avx512Set() {
  using raster_kernels::KernelSet;
  static const std::optional<KernelSet> set = []() -> std::optional<KernelSet> {
    if (!raster_kernels::CompiledKernels<raster_kernels::Avx2Isa>::set ||
        !raster_kernels::CompiledKernels<raster_kernels::Avx512Isa>::set)
      return std::nullopt;
    KernelSet s = *raster_kernels::CompiledKernels<raster_kernels::Avx2Isa>::set;
    const KernelSet& w = *raster_kernels::CompiledKernels<raster_kernels::Avx512Isa>::set;
    s.name = w.name;
    s.backward = w.backward;
    s.fisher = w.fisher;
    s.composite_pair = w.composite_pair;
    s.backward_pair = w.backward_pair;
    return s;
  }();
  return set ? &*set : nullptr;
}

}  // namespace

const raster_kernels::KernelSet& kernelSet(RasterKernels kernels) {
  switch (kernelIndex(kernels)) {
    case 1:
      return *raster_kernels::CompiledKernels<raster_kernels::Avx2Isa>::set;
    case 2:
      return *avx512Set();
    default:
      return *raster_kernels::CompiledKernels<raster_kernels::BaselineIsa>::set;
  }
}

}  // namespace raster_execution

std::optional<RasterKernels> parseRasterKernels(std::string_view name) {
  if (name == "default") return RasterKernels::kDefault;
  if (name == "baseline") return RasterKernels::kBaseline;
  if (name == "avx2") return RasterKernels::kAvx2;
  if (name == "avx512") return RasterKernels::kAvx512;
  return std::nullopt;
}

bool rasterCpuHasAvx2() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  static const bool has = raster_kernels::CompiledKernels<raster_kernels::Avx2Isa>::set &&
                          __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has;
#else
  return false;
#endif
}

bool rasterCpuHasAvx512() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  static const bool has = rasterCpuHasAvx2() && raster_kernels::CompiledKernels<raster_kernels::Avx512Isa>::set &&
                          __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl");
  return has;
#else
  return false;
#endif
}

double rasterForwardFloorNsPerPair(const RasterExecution& e, double seconds) {
  const raster_kernels::KernelSet& kernels = raster_execution::kernelSet(e.kernels);
  const raster_kernels::CompositeFloorFn run = kernels.composite_floor;  // avx512's is avx2's
  const int lanes = kernels.lanes;
  volatile float sink = run(1000);  // warm up
  // Doubles the rounds until one timing lasts `seconds`, then takes the best of three.
  long n = 1 << 14;
  double best = 0;
  for (;;) {
    const auto t0 = std::chrono::steady_clock::now();
    sink = run(n);
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (t >= seconds || n > (1L << 40)) {
      best = t;
      for (int r = 0; r < 2; ++r) {
        const auto t1 = std::chrono::steady_clock::now();
        sink = run(n);
        best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count());
      }
      break;
    }
    n *= 2;
  }
  (void)sink;
  return 1e9 * best / (static_cast<double>(n) * 2.0 * lanes);
}

int rasterThreadCount(const RasterExecution& e) { return raster_execution::arena(e.threads).max_concurrency(); }

}  // namespace saresgs
