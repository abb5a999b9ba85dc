#pragma once
// Real spherical-harmonics basis up to degree 3 in the convention of 3DGS (the
// constants are those of the standard real SH, with 3DGS's signs). Templated so that
// the float fast path and the double reference share one definition of the basis.
#include "splat/gaussians.h"
#include "splat/raster/sh_constants.h"

namespace saresgs {

// Writes the shCoeffCount(degree) basis values Y_k(d) for a unit direction d.
template <typename T>
void shBasis(int degree, T x, T y, T z, T* out) {
  using namespace sh_constants;
  out[0] = T(kShC0);
  if (degree < 1) return;
  out[1] = -T(C1) * y;
  out[2] = T(C1) * z;
  out[3] = -T(C1) * x;
  if (degree < 2) return;
  const T xx = x * x, yy = y * y, zz = z * z, xy = x * y, yz = y * z, xz = x * z;
  out[4] = T(C2[0]) * xy;
  out[5] = T(C2[1]) * yz;
  out[6] = T(C2[2]) * (T(2) * zz - xx - yy);
  out[7] = T(C2[3]) * xz;
  out[8] = T(C2[4]) * (xx - yy);
  if (degree < 3) return;
  out[9] = T(C3[0]) * y * (T(3) * xx - yy);
  out[10] = T(C3[1]) * xy * z;
  out[11] = T(C3[2]) * y * (T(4) * zz - xx - yy);
  out[12] = T(C3[3]) * z * (T(2) * zz - T(3) * xx - T(3) * yy);
  out[13] = T(C3[4]) * x * (T(4) * zz - xx - yy);
  out[14] = T(C3[5]) * z * (xx - yy);
  out[15] = T(C3[6]) * x * (xx - T(3) * yy);
}

}  // namespace saresgs
