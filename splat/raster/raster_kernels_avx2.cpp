// The float tile kernels eight lanes wide for CPUs with AVX2 (splat/raster/raster_kernels.h).
// Built with -mavx2 -mfma -ffp-contract=off on x86-64 (splat/CMakeLists.txt), which
// defines SARESGS_RASTER_AVX2; elsewhere its set is null. The
// rasterizer calls these only when the CPU reports AVX2 and FMA.
#include "splat/raster/raster_kernels.h"

#if defined(SARESGS_RASTER_AVX2)
namespace saresgs::raster_kernels {
using KernelIsa = Avx2Isa;
}

#include "splat/raster/raster_kernels_set_impl.h"
#else
template <>
const saresgs::raster_kernels::KernelSet* const
    saresgs::raster_kernels::CompiledKernels<saresgs::raster_kernels::Avx2Isa>::set = nullptr;
#endif
