#pragma once
// The FisherRF protocol's initial views: train index 0, then farthest-point sampling
// of the camera centres (each next view maximises its distance to the chosen ones).
#include <Eigen/Core>
#include <vector>

namespace saresgs {

// Returns `count` indices into `centers` (fewer when there are fewer centres), the
// first being `first`. Ties go to the lowest index, so the result is deterministic.
std::vector<int> farthestPointSampling(const std::vector<Eigen::Vector3d>& centers, int count, int first = 0);

}  // namespace saresgs
