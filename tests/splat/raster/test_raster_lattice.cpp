// The tile kernels' pixel walk (forEachBlock in splat/raster/raster_kernels_impl.h) gives
// each block's G = exp(-1/2 d^T conic d) either from an exponential per block or, where
// the Gaussian's block rectangle suits it, from the lattice: three exponentials at the
// first block and products of step factors after it. Both against exp in double, on
// round, needle-like, tiny and huge Gaussians, near the origin and far from it, with and
// without chords; the kernels' own instruction sets are checked end to end by
// FloatPath.* and FastVsReference.*. This file compiles the walk for the eight-lane block
// shape (four columns by two rows) with the baseline compiler flags, test_raster_lattice4.cpp
// for the four-lane one; the check itself is in lattice_walk.h.
#include "splat/raster/raster_kernels.h"

namespace saresgs::raster_kernels {
using KernelIsa = KernelOptions<8, false, false>;  // 8 lanes, the baseline flags
}

#include "tests/splat/raster/lattice_walk.h"

namespace saresgs::raster_kernels {
namespace {

TEST(TileWalk, EightLanesGAgreesWithDoubleOnTheLatticeAndOff) { checkRandomWalks("8 lanes"); }

// Gaussians whose rectangle's corners sit just above and just below the lattice's floor
// (2^-100): thin ones across the tile's diagonal, where G spans the whole float range.
TEST(TileWalk, NeedlesAtTheLatticeFloor) {
  WalkStats st;
  long fits = 0, tried = 0;
  for (double s2 = 0.35; s2 < 3.0; s2 *= 1.07)
    for (double t = 0.3; t < 1.3; t += 0.1) {
      const double s1 = 30.0, ct = std::cos(t), sn = std::sin(t);
      const double sxx = s1 * s1 * ct * ct + s2 * s2 * sn * sn, syy = s1 * s1 * sn * sn + s2 * s2 * ct * ct;
      const double sxy = (s1 * s1 - s2 * s2) * ct * sn, det = sxx * syy - sxy * sxy;
      const Spec s{7.3, 8.6, syy / det, -sxy / det, sxx / det, 0.8};
      const TileGaussian<float> g = tileGaussian(s, false);
      Lattice lt;
      int c0, c1, r0, r1;
      tileSpan(g.px0, g.px1, 0, 16, c0, c1);
      tileSpan(g.py0, g.py1, 0, 16, r0, r1);
      fits += latticeFits(g, 0, 0, c0 & ~3, c1 & ~3, r0 / 2, r1 / 2, lt);
      ++tried;
      walk(s, false, 0, 0, st);
      if (HasFatalFailure()) return;
    }
  EXPECT_GT(fits, tried / 5);
  EXPECT_LT(fits, tried * 4 / 5);
}

}  // namespace
}  // namespace saresgs::raster_kernels
