// The kernels that gain from 32 vector registers, for CPUs with AVX-512F and AVX-512VL
// (splat/raster/raster_kernels.h): the AVX2 kernels' eight lanes and arithmetic, compiled
// with -mavx512f -mavx512vl -mfma -ffp-contract=off (splat/CMakeLists.txt, which defines
// SARESGS_RASTER_AVX512 on x86-64).
// - fisherTile: the walk keeps all 19 moment accumulators in registers and sums them as
//   it goes (KernelIsa::kFisherOnePass in raster_kernels_backward_impl.h), instead of storing
//   each block's two inputs and summing them in three later passes.
// - compositeTilePair and backwardTilePair (residual supervision's two renders in one
//   walk): the pair loops' Gaussian constants and the backward's nine gradient sums, which
//   spill on AVX2's 16 registers, stay in registers. The selects of backStep are bitwise
//   ands (maskOr0 in raster_kernels_impl.h, the same bits): written as `gm ? x : 0`, GCC
//   builds their two-compare mask lane by lane in general-purpose registers instead of
//   AVX-512's mask registers, and the kernel loses to AVX2's. The pair backward on
//   AVX-512VL takes 0.75-0.78x the AVX2 kernel's time (bench train --residual, room360
//   256x192).
// - backwardTile: its nine gradient sums, the lattice's G, step and row factor and the
//   Gaussian's constants outgrow AVX2's 16 registers; on 32 the backward stage of bench
//   train (room360 512x384) takes 0.94-0.97x the AVX2 kernel's time.
// Each value sees the same operations in the same order, so the outputs are bit-identical
// to the AVX2 kernels' (tested: Fisher.Avx512WalkEqualsAvx2BitForBit,
// FloatPath.Avx512BackwardEqualsAvx2BitForBit, SubsetPair.Avx512BackwardEqualsAvx2BitForBit,
// and SubsetPair.* against the single-render AVX2 kernel on every kernel set). The forward
// kernel gained nothing or lost from the wider register file (docs/DECISIONS.md),
// so the avx512 kernel set takes it, and the projection kernels, from the AVX2 set.
#include "splat/raster/raster_kernels.h"

#if defined(SARESGS_RASTER_AVX512)
namespace saresgs::raster_kernels {
using KernelIsa = Avx512Isa;
}

#include "splat/raster/raster_kernels_pair_impl.h"

namespace saresgs::raster_kernels {
namespace {
constexpr KernelSet kWalks = walkKernels();
}  // namespace

template <>
const KernelSet* const CompiledKernels<Avx512Isa>::set = &kWalks;
}  // namespace saresgs::raster_kernels
#else
template <>
const saresgs::raster_kernels::KernelSet* const
    saresgs::raster_kernels::CompiledKernels<saresgs::raster_kernels::Avx512Isa>::set = nullptr;
#endif
