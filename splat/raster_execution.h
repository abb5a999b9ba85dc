#pragma once
// How the rasterizer runs: the threads of its TBB arena and its float SIMD kernels. A
// field of RasterSettings (splat/rasterize.h), so each render says how it runs and no
// process-wide state does. Results do not depend on the thread count (every reduction
// runs in a fixed order); the baseline and avx2 kernel sets differ only in rounding, and
// avx512 gives avx2's results bit for bit. A render's
// backward and squared-gradient passes run with its forward pass's execution.
#include <optional>
#include <string_view>

namespace saresgs {

// kDefault: avx512 when the CPU has AVX-512F and VL, else avx2 when it has AVX2 and FMA,
// unless SARESGS_RASTER_ISA (baseline, avx2, avx512 or default) names the kernels in the
// environment (kernels the CPU lacks, or another value: std::invalid_argument at the first
// render); kBaseline: four
// lanes, any target; kAvx2: eight lanes; kAvx512: the avx2 kernels, bit for bit the same
// results, with the Fisher pass's walk on AVX-512VL's 32 registers (one pass instead of
// three over each Gaussian's blocks; the forward and backward are avx2's).
enum class RasterKernels { kDefault, kBaseline, kAvx2, kAvx512 };

struct RasterExecution {
  int threads = 0;  // the rasterizer's arena; 0: all cores
  RasterKernels kernels = RasterKernels::kDefault;
};

// "default", "baseline", "avx2" or "avx512"; nullopt for any other name.
std::optional<RasterKernels> parseRasterKernels(std::string_view name);
// Whether this build and CPU can run the avx2 kernels.
bool rasterCpuHasAvx2();
// Whether this build and CPU can run the avx512 kernels (AVX2, FMA, AVX-512F and VL).
bool rasterCpuHasAvx512();
// The threads a render with `e` runs on (the arena's concurrency: `threads`, or all cores).
int rasterThreadCount(const RasterExecution& e);
// The kernels a render with `e` uses, "baseline", "avx2" or "avx512" (kDefault resolved).
// Throws std::invalid_argument for kernels the CPU lacks, as rendering with `e` does.
const char* rasterKernelName(const RasterExecution& e);

// The forward kernel's per-pair arithmetic alone (on the lattice: G's two products, alpha,
// tests and the compositing step, on register-resident pixels: no tile walk, no first
// block's exponentials, no memory traffic), timed
// on the calling thread with e's kernels for about `seconds`: nanoseconds per
// Gaussian-pixel pair on one core, the floor against which `bench step` reports a pass.
double rasterForwardFloorNsPerPair(const RasterExecution& e, double seconds = 0.2);

}  // namespace saresgs
