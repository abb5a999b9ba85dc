#pragma once
// FisherRF's view information (splat/fisher.h) templated on the scalar: float is the
// product, double serves the finite-difference tests. For splat/ sources and tests only.
#include "geometry/camera/camera.h"
#include "splat/gaussians.h"
#include "splat/raster/rasterize_detail.h"

namespace saresgs {

// Adds view `cam`'s information to `H` (same shape as g; rotations untouched).
template <typename T>
void addViewInformationT(const GaussiansT<T>& g, const Camera& cam, const RasterSettings& s, GaussiansT<T>& H) {
  const RenderOutputT<T> fwd = rasterizeT(g, cam, s);
  rasterizeSquaredGradientsT(g, cam, s, fwd, H);
}

}  // namespace saresgs
