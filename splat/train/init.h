#pragma once
// Initial Gaussians, as 3DGS makes them: one isotropic Gaussian per point with scale
// log(sqrt(mean squared distance to its 3 nearest neighbours)), identity rotation,
// opacity 0.1 and the point's colour in the DC coefficient; or, for a dataset without
// points, grey random points in a ball.
#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "splat/gaussians.h"

namespace saresgs {

struct ColoredPoint {
  Eigen::Vector3d xyz;
  std::array<float, 3> rgb;  // [0, 1]
};

// Mean squared distance of each point to its 3 nearest other points (fewer when there
// are fewer points; 1e-7 floor, as 3DGS clamps, so that duplicate points stay finite).
std::vector<double> meanSquaredKnnDistance(const std::vector<Eigen::Vector3d>& pts, int k = 3);

// Throws std::invalid_argument for an empty point list or a negative degree.
Gaussians gaussiansFromPoints(const std::vector<ColoredPoint>& pts, int max_sh_degree, float initial_opacity = 0.1f);

// n points uniform in the ball of `radius` about `center` (rejection sampling from its
// cube), grey (0.5): 3DGS's synthetic-scene init draws its colours as SH coefficients in
// [0, 1/255), i.e. grey to within 0.1 %.
std::vector<ColoredPoint> randomPointsInBall(const Eigen::Vector3d& center, double radius, int n, std::mt19937_64& rng);

}  // namespace saresgs
