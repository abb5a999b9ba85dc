#include "splat/train/init.h"
#include "geometry/float_env.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace saresgs {

namespace {

// A k-d tree over point indices (median splits along the widest axis), so that the
// query cost does not depend on how the points are spread: lines, sheets, clusters and
// far outliers are all O(log n) per query.
class KdTree {
 public:
  explicit KdTree(const std::vector<Eigen::Vector3d>& pts) : pts_(pts), idx_(pts.size()) {
    for (std::size_t i = 0; i < idx_.size(); ++i) idx_[i] = static_cast<int>(i);
    nodes_.reserve(2 * pts.size() / kLeaf + 2);
    build(0, idx_.size());
  }
  // The k smallest squared distances from point `self` to other points, ascending.
  void nearest(int self, std::vector<double>& best) const { search(0, self, best); }

 private:
  static constexpr std::size_t kLeaf = 8;
  struct Node {
    std::size_t begin, end;
    int axis = -1;  // -1: leaf
    double split = 0;
    int left = -1, right = -1;
  };

  int build(std::size_t b, std::size_t e) {
    const int id = static_cast<int>(nodes_.size());
    nodes_.push_back({b, e});
    if (e - b <= kLeaf) return id;
    Eigen::Vector3d lo = pts_[idx_[b]], hi = lo;
    for (std::size_t i = b; i < e; ++i) {
      lo = lo.cwiseMin(pts_[idx_[i]]);
      hi = hi.cwiseMax(pts_[idx_[i]]);
    }
    int axis;
    (hi - lo).maxCoeff(&axis);
    const std::size_t mid = b + (e - b) / 2;
    std::nth_element(idx_.begin() + static_cast<std::ptrdiff_t>(b), idx_.begin() + static_cast<std::ptrdiff_t>(mid),
                     idx_.begin() + static_cast<std::ptrdiff_t>(e),
                     [&](int x, int y) { return pts_[x][axis] < pts_[y][axis]; });
    const double split = pts_[idx_[mid]][axis];
    const int left = build(b, mid);
    const int right = build(mid, e);
    nodes_[id].axis = axis;
    nodes_[id].split = split;
    nodes_[id].left = left;
    nodes_[id].right = right;
    return id;
  }

  void search(int id, int self, std::vector<double>& best) const {
    const Node& n = nodes_[static_cast<std::size_t>(id)];
    const Eigen::Vector3d& q = pts_[static_cast<std::size_t>(self)];
    if (n.axis < 0) {
      for (std::size_t i = n.begin; i < n.end; ++i) {
        if (idx_[i] == self) continue;
        const double d2 = (pts_[idx_[i]] - q).squaredNorm();
        if (d2 < best.back()) {
          best.back() = d2;
          std::sort(best.begin(), best.end());
        }
      }
      return;
    }
    const double diff = q[n.axis] - n.split;
    const int near = diff < 0 ? n.left : n.right, far = diff < 0 ? n.right : n.left;
    search(near, self, best);
    if (diff * diff <= best.back()) search(far, self, best);
  }

  const std::vector<Eigen::Vector3d>& pts_;
  std::vector<int> idx_;
  std::vector<Node> nodes_;
};

}  // namespace

std::vector<double> meanSquaredKnnDistance(const std::vector<Eigen::Vector3d>& pts, int k) {
  const std::size_t n = pts.size();
  std::vector<double> out(n, 1e-7);
  if (n < 2 || k < 1) return out;
  const KdTree tree(pts);
  const std::size_t kk = std::min<std::size_t>(static_cast<std::size_t>(k), n - 1);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
    const FloatEnvGuard fenv;  // geometry/float_env.h
    std::vector<double> best;
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      best.assign(kk, std::numeric_limits<double>::infinity());
      tree.nearest(static_cast<int>(i), best);
      double sum = 0;
      for (double d : best) sum += d;
      out[i] = std::max(sum / static_cast<double>(kk), 1e-7);
    }
  });
  return out;
}

Gaussians gaussiansFromPoints(const std::vector<ColoredPoint>& pts, int max_sh_degree, float initial_opacity) {
  if (pts.empty()) throw std::invalid_argument("gaussiansFromPoints: no points");
  if (max_sh_degree < 0 || max_sh_degree > 3)
    throw std::invalid_argument("gaussiansFromPoints: SH degree must be 0..3");
  std::vector<Eigen::Vector3d> xyz(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) xyz[i] = pts[i].xyz;
  const std::vector<double> d2 = meanSquaredKnnDistance(xyz);
  Gaussians g;
  g.max_sh_degree = max_sh_degree;
  g.resize(pts.size());
  const int K = g.shCoeffs();
  const float logit = std::log(initial_opacity / (1.0f - initial_opacity));
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const float ls = static_cast<float>(0.5 * std::log(d2[i]));  // log(sqrt(d2))
    for (int k = 0; k < 3; ++k) {
      g.means[3 * i + k] = static_cast<float>(xyz[i][k]);
      g.log_scales[3 * i + k] = ls;
      g.sh[(i * K) * 3 + k] = static_cast<float>((pts[i].rgb[k] - 0.5) / kShC0);
    }
    g.rotations[4 * i] = 1.0f;
    g.opacities[i] = logit;
  }
  return g;
}

std::vector<ColoredPoint> randomPointsInBall(const Eigen::Vector3d& center, double radius, int n,
                                             std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<ColoredPoint> out;
  out.reserve(static_cast<std::size_t>(std::max(n, 0)));
  while (static_cast<int>(out.size()) < n) {
    const Eigen::Vector3d q(u(rng), u(rng), u(rng));
    if (q.squaredNorm() <= 1.0) out.push_back({center + radius * q, {0.5f, 0.5f, 0.5f}});
  }
  return out;
}

}  // namespace saresgs
