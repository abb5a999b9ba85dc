#pragma once
// Internal to the rasterizer: a RasterExecution (splat/raster_execution.h) resolved to
// the TBB arena and the float kernels a pass runs on.
#include <tbb/task_arena.h>

#include "splat/raster_execution.h"

namespace saresgs::raster_kernels {
struct KernelSet;
}

namespace saresgs::raster_execution {

// The arena of `threads` (<= 0: all cores), made on first use and kept for the process
// (TBB keeps its worker threads alive between calls), one per thread count asked for.
tbb::task_arena& arena(int threads);

// The float kernels `kernels` resolves to (splat/raster/raster_kernels.h). Throws
// std::invalid_argument for kernels the CPU or build lacks, and for kDefault when
// SARESGS_RASTER_ISA names no kernels this CPU runs.
const raster_kernels::KernelSet& kernelSet(RasterKernels kernels);

}  // namespace saresgs::raster_execution
