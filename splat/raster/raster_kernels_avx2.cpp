// The float tile kernels eight lanes wide for CPUs with AVX2 (splat/raster/raster_kernels.h).
// Built with -mavx2 -mfma -ffp-contract=off on x86-64 (splat/CMakeLists.txt), which
// defines SARESGS_RASTER_AVX2; elsewhere only compiled() exists and says false. The
// rasterizer calls these only when the CPU reports AVX2 and FMA.
#include "splat/raster/raster_kernels.h"

#if defined(SARESGS_RASTER_AVX2)
#define SARESGS_KERNEL_NS avx2
#define SARESGS_KERNEL_LANES 8
#define SARESGS_KERNEL_FMA 1
#include "splat/raster/raster_kernels_impl.h"
#include "splat/raster/raster_kernels_backward_impl.h"
#include "splat/raster/raster_kernels_pair_impl.h"
#include "splat/raster/project_kernels_impl.h"

namespace saresgs::raster_kernels::avx2 {
bool compiled() { return true; }
}  // namespace saresgs::raster_kernels::avx2
#else
#include <cstdlib>

namespace saresgs::raster_kernels::avx2 {
bool compiled() { return false; }
void projectRange(const ProjectIn&, std::size_t, std::size_t, projection::Projected<float>*) { std::abort(); }
void projectBackwardList(const ProjectIn&, const std::uint32_t*, int, const projection::Projected<float>*,
                         const projection::ProjectedGrad<float>*, const ProjectGradOut&) {
  std::abort();
}
void fisherChainList(const ProjectIn&, const std::uint32_t*, int, const projection::Projected<float>*, const double*,
                     const FisherGradOut&) {
  std::abort();
}
float compositeFloor(long) { std::abort(); }
void compositeTile(const TileGaussian<float>*, int, int, int, int, int, const float*, const ForwardOut&) {
  std::abort();
}
void backwardTile(const TileGaussian<float>*, int, int, int, int, int, const float*, const BackwardIn&,
                  const std::uint32_t*, float*) {
  std::abort();
}
void fisherTile(const TileGaussian<float>*, int, int, int, int, int, const float*, const FisherIn&,
                const std::uint32_t*, float*) {
  std::abort();
}
}  // namespace saresgs::raster_kernels::avx2

namespace saresgs::raster_kernels::avx2 {
void compositeTilePair(const TileGaussian<float>*, const std::uint8_t*, int, int, int, int, int, const float*,
                       const ForwardOut&, const ForwardOut&) {
  std::abort();
}
void backwardTilePair(const TileGaussian<float>*, const std::uint8_t*, int, int, int, int, int, const float*,
                      const BackwardIn&, const BackwardIn&, const std::uint32_t*, float*) {
  std::abort();
}
}  // namespace saresgs::raster_kernels::avx2
#endif
