// The kernels that gain from 32 vector registers, for CPUs with AVX-512F and AVX-512VL
// (splat/raster/raster_kernels.h): the AVX2 kernels' eight lanes and arithmetic, compiled
// with -mavx512f -mavx512vl -mfma -ffp-contract=off (splat/CMakeLists.txt, which defines
// SARESGS_RASTER_AVX512 on x86-64).
// - fisherTile: the walk keeps all 19 moment accumulators in registers and sums them as
//   it goes (SARESGS_KERNEL_FISHER_ONE_PASS in raster_kernels_impl.h), instead of storing
//   each block's two inputs and summing them in three later passes.
// - compositeTilePair (residual supervision's two renders in one walk): the pair loop's
//   Gaussian constants, which spill on AVX2's 16 registers, stay in registers.
// Each value sees the same operations in the same order, so the outputs are bit-identical
// to the AVX2 kernels' (tested: Fisher.Avx512WalkEqualsAvx2BitForBit, and SubsetPair.*
// against the single-render AVX2 kernel on every kernel set). The other kernels, the pair
// backward included, gained nothing or lost from the wider register file
// (docs/PERFORMANCE_TRIED.md), so the avx512 kernel set uses the AVX2 ones.
#include "splat/raster/raster_kernels.h"

#if defined(SARESGS_RASTER_AVX512)
#define SARESGS_KERNEL_NS avx512
#define SARESGS_KERNEL_LANES 8
#define SARESGS_KERNEL_FMA 1
#define SARESGS_KERNEL_FISHER_ONE_PASS 1
#define SARESGS_KERNEL_FISHER_ONLY 1
#define SARESGS_KERNEL_PAIR_COMPOSITE_ONLY 1
#include "splat/raster/raster_kernels_impl.h"
#include "splat/raster/raster_kernels_pair_impl.h"

namespace saresgs::raster_kernels::avx512 {
bool compiled() { return true; }
}  // namespace saresgs::raster_kernels::avx512
#else
#include <cstdlib>

namespace saresgs::raster_kernels::avx512 {
bool compiled() { return false; }
void fisherTile(const TileGaussian<float>*, int, int, int, int, int, const float*, const FisherIn&,
                const std::uint32_t*, float*) {
  std::abort();
}
void compositeTilePair(const TileGaussian<float>*, const std::uint8_t*, int, int, int, int, int, const float*,
                       const ForwardOut&, const ForwardOut&) {
  std::abort();
}
}  // namespace saresgs::raster_kernels::avx512
#endif
