#include "splat/model_frame.h"

#include <cmath>

namespace saresgs {

namespace {

// x' = a x + b for the means (in double), log s' = log s + log a for the scales.
Gaussians mapped(const Gaussians& g, double a, const Eigen::Vector3d& b) {
  Gaussians out = g;
  for (std::size_t i = 0; i < g.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const std::size_t j = 3 * i + static_cast<std::size_t>(k);
      out.means[j] = static_cast<float>(a * static_cast<double>(g.means[j]) + b[k]);
      out.log_scales[j] = static_cast<float>(static_cast<double>(g.log_scales[j]) + std::log(a));
    }
  return out;
}

}  // namespace

Gaussians gaussiansToWorld(const Gaussians& internal, const SceneFrame& frame) {
  if (frame.identity()) return internal;
  return mapped(internal, frame.scale, frame.center);
}

Gaussians gaussiansFromWorld(const Gaussians& world, const SceneFrame& frame) {
  if (frame.identity()) return world;
  return mapped(world, 1.0 / frame.scale, -frame.center / frame.scale);
}

}  // namespace saresgs
