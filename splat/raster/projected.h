#pragma once
// One Gaussian's projected form (rules 1-5 of splat/rasterize.h) and its gradient, apart from
// splat/raster/projection.h so that the SIMD projection kernels
// (splat/raster/project_kernels_impl.h), which include no header with inline code of its
// own, write the same struct.

namespace saresgs::projection {

// The projected form of one Gaussian.
template <typename T>
struct Projected {
  bool visible = false;
  T mean2d[2];
  T conic[3];  // inverse 2D covariance (a, b, c)
  T cov2d[3];  // 2D covariance incl. eps2d (a, b, c)
  T depth;     // camera z
  T opacity;
  T color[3];
  bool clamped[3];  // colour channel clamped at 0 (no gradient)
  T half[2];        // rectangle half sizes in px
  T radius;
};

// Gradients of the projected quantities of one Gaussian.
template <typename T>
struct ProjectedGrad {
  T mean2d[2] = {0, 0};
  T conic[3] = {0, 0, 0};
  T color[3] = {0, 0, 0};
  T opacity = 0;  // dL/d(sigmoid opacity)
};

}  // namespace saresgs::projection
