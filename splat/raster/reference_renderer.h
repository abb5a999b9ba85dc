#pragma once
// The slow, obviously correct renderer: rules 1-8 of splat/rasterize.h applied per
// pixel, in double precision, with no tiles and no shortcuts. The fast tiled path is
// tested against it, and its parameters are doubles so that tests can take finite
// differences of single parameters.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "geometry/camera/camera.h"
#include "splat/gaussians.h"
#include "splat/rasterize.h"

namespace saresgs {

struct ReferenceImage {  // double precision outputs, row-major
  int width = 0, height = 0;
  std::vector<double> rgb;  // 3 per pixel
  std::vector<double> alpha, depth;
  std::vector<int> contributors;
  std::vector<double> radii;  // per Gaussian, 0 when culled
  std::vector<std::uint8_t> visible;
};

// The model in double (GaussiansD, splat/gaussians.h) so that tests can perturb one
// parameter and re-render for finite differences.
inline GaussiansD toDouble(const Gaussians& g) { return g.cast<double>(); }

// Renders `g` from `cam` into a cam.K.width x cam.K.height image. `mask` is empty (all
// rendered) or holds one entry per Gaussian (0 = rendered as if its opacity were 0).
// Throws std::invalid_argument when the arrays do not match the model's size, the
// mask has the wrong size, or the active SH degree is not in [0, max_sh_degree].
ReferenceImage referenceRender(const GaussiansD& g, const Camera& cam, const RasterSettings& s,
                               std::span<const std::uint8_t> mask = {});

}  // namespace saresgs
