#include "nbv/initial_views.h"

#include <limits>
#include <stdexcept>

namespace saresgs {

std::vector<int> farthestPointSampling(const std::vector<Eigen::Vector3d>& centers, int count, int first) {
  std::vector<int> chosen;
  if (centers.empty() || count <= 0) return chosen;
  if (first < 0 || first >= static_cast<int>(centers.size()))
    throw std::out_of_range("farthestPointSampling: first index out of range");
  std::vector<double> dist(centers.size(), std::numeric_limits<double>::infinity());
  int next = first;
  while (static_cast<int>(chosen.size()) < count && next >= 0) {
    chosen.push_back(next);
    for (size_t i = 0; i < centers.size(); ++i) dist[i] = std::min(dist[i], (centers[i] - centers[next]).squaredNorm());
    next = -1;
    double best = -1;
    for (size_t i = 0; i < centers.size(); ++i)
      if (dist[i] > best && dist[i] > 0) {  // strict '>' keeps the lowest index on ties
        best = dist[i];
        next = static_cast<int>(i);
      }
  }
  return chosen;
}

}  // namespace saresgs
