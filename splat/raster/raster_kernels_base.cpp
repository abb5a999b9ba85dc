// The baseline (four-lane) float tile kernels, portable to any x86-64 or other CPU
// (splat/raster/raster_kernels.h); the AVX2 and AVX-512VL ones are in
// raster_kernels_avx2.cpp and raster_kernels_avx512.cpp.
#include "splat/raster/raster_kernels.h"

namespace saresgs::raster_kernels {
using KernelIsa = BaselineIsa;
}

#include "splat/raster/raster_kernels_set_impl.h"
