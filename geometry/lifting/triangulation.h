#pragma once
// Two-view triangulation by the normalised linear (DLT) method, in double, with the
// checks that decide whether a triangulated point is trusted. No NaN or Inf ever leaves
// these functions: every degenerate case is a rejection with a reason.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "geometry/camera/camera.h"
#include "geometry/lifting/correspondence.h"

namespace saresgs {

// Why a correspondence gave no point, in the order the checks run.
enum class Rejection : std::uint8_t {
  kNone = 0,      // kept
  kBorder,        // a point is not finite or lies within border_px of an image edge (or outside)
  kZeroBaseline,  // the two camera centres coincide: depth is unobservable
  kDegenerate,    // the linear system has no unique solution (e.g. a ray through the other centre)
  kAtInfinity,    // the solution is a direction, not a point
  kBehindCamera,  // depth <= near in at least one camera
  kParallelRays,  // the rays meet at an angle below min_ray_angle_deg
  kReprojection,  // mean reprojection error >= max_reprojection_px
};
inline constexpr int kRejectionCount = 8;
const char* rejectionName(Rejection r);

struct TriangulationOptions {
  double max_reprojection_px = 1.0;  // paper: kept when the mean two-view error is < 1 px
  // Rays closer to parallel fix depth poorly: depth error per pixel of matching error grows
  // as 1 / angle. 2 degrees, not 1: on the synthetic room at 256x192 with the flow module,
  // 1 degree keeps 17 % more points but 87 % instead of 93 % of them lie within 2 voxels
  // (1/128 of the scene box) of the surface; the extra points are far walls seen near the
  // epipole.
  double min_ray_angle_deg = 2.0;
  double near = 1e-6;      // minimum depth along each camera's z axis, world units
  double border_px = 1.0;  // both points must lie in [b, W - b] x [b, H - b]
};

struct TriangulatedPoint {
  Eigen::Vector3d X = Eigen::Vector3d::Zero();  // finite; zero when no point was solved
  double reprojection_px = -1;                  // mean of the two pixel errors; -1 when no point was solved
  Rejection rejection = Rejection::kNone;
  bool kept() const { return rejection == Rejection::kNone; }
};

// The linear solution alone. status is kNone, kZeroBaseline, kDegenerate or kAtInfinity;
// X is finite and meaningful only with kNone. P0, P1 are 3x4 projection matrices of finite
// cameras (the left 3x3 block invertible), x0, x1 pixel coordinates in the same convention.
struct DltSolution {
  Eigen::Vector3d X = Eigen::Vector3d::Zero();
  Rejection status = Rejection::kNone;
};
DltSolution triangulateDLT(const Eigen::Matrix<double, 3, 4>& P0, const Eigen::Matrix<double, 3, 4>& P1,
                           const Eigen::Vector2d& x0, const Eigen::Vector2d& x1);

// One correspondence between cam0 and cam1: DLT from their projection matrices, then the
// checks of Rejection in order.
TriangulatedPoint triangulate(const Camera& cam0, const Camera& cam1, const Correspondence& m,
                              const TriangulationOptions& opts = {});

// All correspondences, TBB-parallel; out[i] belongs to matches[i], so the result does not
// depend on the thread count.
std::vector<TriangulatedPoint> triangulateAll(const Camera& cam0, const Camera& cam1,
                                              std::span<const Correspondence> matches,
                                              const TriangulationOptions& opts = {});

}  // namespace saresgs
