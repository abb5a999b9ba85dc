// The tile kernels' pixel walk for the four-lane block shape (four columns by one row),
// with the baseline compiler flags: the check of test_raster_lattice.cpp (lattice_walk.h)
// on the kernels' other block shape.
#include "splat/raster/raster_kernels.h"

namespace saresgs::raster_kernels {
using KernelIsa = KernelOptions<4, false, false>;  // 4 lanes, the baseline flags
}

#include "tests/splat/raster/lattice_walk.h"

TEST(TileWalk, FourLanesGAgreesWithDoubleOnTheLatticeAndOff) { saresgs::raster_kernels::checkRandomWalks("4 lanes"); }
