#pragma once
// FisherRF's view information (splat/fisher.h) templated on the scalar: float is the
// product, double serves the finite-difference tests. For splat/ sources and tests only.
#include "geometry/camera/camera.h"
#include "splat/gaussians.h"
#include "splat/raster/rasterize_detail.h"

namespace saresgs {

// Adds view `cam`'s information to `H` (same shape as g; rotations untouched).
// The squared-gradient pass reads the render's state (final transmittance, walk lengths),
// never its depth or contributor counts, so the render leaves them out.
template <typename T>
void addViewInformationT(const GaussiansT<T>& g, const Camera& cam, const RasterSettings& settings, GaussiansT<T>& H) {
  RasterSettings s = settings;
  s.depth_and_contributors = false;
  const RenderOutputT<T> fwd = rasterizeT(g, cam, s);
  rasterizeSquaredGradientsT(g, cam, s, fwd, H);
}

}  // namespace saresgs
