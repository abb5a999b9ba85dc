#pragma once
// The real spherical-harmonics constants of degrees 1-3 (splat/raster/sh.h), in a header
// with no includes so that the SIMD projection kernels share them.

namespace saresgs {

namespace sh_constants {
inline constexpr double C1 = 0.4886025119029199;
inline constexpr double C2[5] = {1.0925484305920792, -1.0925484305920792, 0.31539156525252005, -1.0925484305920792,
                                 0.5462742152960396};
inline constexpr double C3[7] = {-0.5900435899266435, 2.890611442640554, -0.4570457994644658, 0.3731763325901154,
                                 -0.4570457994644658, 1.445305721320277, -0.5900435899266435};
}  // namespace sh_constants

}  // namespace saresgs
