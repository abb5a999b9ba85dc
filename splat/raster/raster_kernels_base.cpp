// The baseline (four-lane) float tile kernels, portable to any x86-64 or other CPU
// (splat/raster/raster_kernels.h); the AVX2 and AVX-512VL ones are in
// raster_kernels_avx2.cpp and raster_kernels_avx512.cpp.
#include "splat/gaussians.h"
#include "splat/raster/raster_kernels.h"
#include "splat/rasterize.h"

#define SARESGS_KERNEL_NS base4
#define SARESGS_KERNEL_LANES 4
#include "splat/raster/raster_kernels_impl.h"
#include "splat/raster/raster_kernels_backward_impl.h"
#include "splat/raster/raster_kernels_pair_impl.h"
#include "splat/raster/project_kernels_impl.h"
#undef SARESGS_KERNEL_NS
#undef SARESGS_KERNEL_LANES

namespace saresgs {
// The kernels restate the contract's constants: they must agree with it.
static_assert(raster_kernels::base4::kProjShC0 == static_cast<float>(kShC0));
static_assert(raster_kernels::base4::kTile == kTileSize && raster_kernels::base4::kMinA == kMinAlpha &&
              raster_kernels::base4::kMaxA == kMaxAlpha && raster_kernels::base4::kMinT == kMinTransmittance);
}  // namespace saresgs
