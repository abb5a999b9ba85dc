#pragma once
// Every kernel of one compilation (the including file's KernelIsa, see
// splat/raster/raster_kernels_impl.h) gathered as the KernelSet the rasterizer calls, and
// defined as CompiledKernels<KernelIsa>::set (raster_kernels.h).
#include "splat/raster/project_kernels_impl.h"
#include "splat/raster/raster_kernels_pair_impl.h"

namespace saresgs::raster_kernels {
namespace {
constexpr KernelSet allKernels() {
  KernelSet s = walkKernels();
  s.composite = compositeTile;
  s.project = projectRange;
  s.project_backward = projectBackwardList;
  s.fisher_chain = fisherChainList;
  s.composite_floor = compositeFloor;
  return s;
}
constexpr KernelSet kCompiledSet = allKernels();
}  // namespace

template <>
const KernelSet* const CompiledKernels<KernelIsa>::set = &kCompiledSet;

}  // namespace saresgs::raster_kernels
