#include "geometry/lifting/triangulation.h"
#include "geometry/enum_names.h"
#include "geometry/float_env.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/LU>
#include <Eigen/SVD>
#include <cmath>
#include <numbers>

namespace saresgs {

using Matrix34d = Eigen::Matrix<double, 3, 4>;

const char* rejectionName(Rejection r) {
  static constexpr std::array<const char*, kRejectionCount> kNames{
      "kept", "border", "zero_baseline", "degenerate", "at_infinity", "behind_camera", "parallel_rays", "reprojection"};
  return enumName(r, kNames, "unknown");
}

namespace {

// Centre of a finite camera: the null vector of P, c = -M^{-1} p4.
bool cameraCentre(const Matrix34d& P, Eigen::Vector3d& c) {
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(P.leftCols<3>());
  if (!lu.isInvertible()) return false;
  c = -lu.solve(P.col(3));
  return c.allFinite();
}

bool insideImage(const Eigen::Vector2d& x, const Intrinsics& K, double border) {
  return x.allFinite() && x.x() >= border && x.y() >= border && x.x() <= K.width - border && x.y() <= K.height - border;
}

struct ProjectionPair {
  Matrix34d P0, P1;
};

TriangulatedPoint triangulateWith(const Camera& cam0, const Camera& cam1, const ProjectionPair& g,
                                  const Correspondence& m, const TriangulationOptions& opts) {
  TriangulatedPoint out;
  if (!insideImage(m.x0, cam0.K, opts.border_px) || !insideImage(m.x1, cam1.K, opts.border_px)) {
    out.rejection = Rejection::kBorder;
    return out;
  }
  const DltSolution s = triangulateDLT(g.P0, g.P1, m.x0, m.x1);
  if (s.status != Rejection::kNone) {
    out.rejection = s.status;
    return out;
  }
  out.X = s.X;
  // The camera's z coordinate is the depth that the near plane refers to.
  const double near = opts.near > 0 ? opts.near : 0.0;
  if (!(cam0.toCamera(s.X).z() > near) || !(cam1.toCamera(s.X).z() > near)) {
    out.rejection = Rejection::kBehindCamera;
    return out;
  }
  // Triangulation angle at the point; atan2 stays accurate for tiny angles, where acos
  // of a dot product loses all digits. Both vectors are non-zero (depth > 0 above).
  const Eigen::Vector3d a = s.X - cam0.center(), b = s.X - cam1.center();
  const double angle = std::atan2(a.cross(b).norm(), a.dot(b));
  const auto p0 = cam0.project(s.X, near), p1 = cam1.project(s.X, near);
  if (!p0 || !p1) {  // cannot happen after the depth test; kept as a guard against NaN
    out.rejection = Rejection::kBehindCamera;
    return out;
  }
  const double err = 0.5 * ((*p0 - m.x0).norm() + (*p1 - m.x1).norm());
  out.reprojection_px = std::isfinite(err) ? err : -1.0;
  if (!(angle >= opts.min_ray_angle_deg * std::numbers::pi / 180.0)) {
    out.rejection = Rejection::kParallelRays;
    return out;
  }
  if (!(err < opts.max_reprojection_px)) out.rejection = Rejection::kReprojection;
  return out;
}

}  // namespace

DltSolution triangulateDLT(const Matrix34d& P0, const Matrix34d& P1, const Eigen::Vector2d& x0,
                           const Eigen::Vector2d& x1) {
  DltSolution out;
  Eigen::Vector3d c0, c1;
  if (!P0.allFinite() || !P1.allFinite() || !x0.allFinite() || !x1.allFinite() || !cameraCentre(P0, c0) ||
      !cameraCentre(P1, c1)) {
    out.status = Rejection::kDegenerate;
    return out;
  }
  const double baseline = (c0 - c1).norm();
  // Relative test: a baseline at the last digits of the centre coordinates is no baseline.
  if (!(baseline > 1e-12 * std::max(c0.norm(), c1.norm()))) {
    out.status = Rejection::kZeroBaseline;
    return out;
  }
  // Normalisation (Hartley): world coordinates X = m + s X' with m the midpoint of the
  // centres and s the baseline, so that the unknowns are O(1) whatever the scene's units
  // and position; in each image the point is moved to the origin, which turns the two
  // equations of a view into "the first two rows of T P annihilate X"; each row is then
  // scaled to unit length so that both views weigh the same.
  Eigen::Matrix4d S = Eigen::Matrix4d::Identity();
  S.topLeftCorner<3, 3>() *= baseline;
  S.topRightCorner<3, 1>() = 0.5 * (c0 + c1);
  const Matrix34d Q0 = P0 * S, Q1 = P1 * S;
  Eigen::Matrix4d A;
  A.row(0) = Q0.row(0) - x0.x() * Q0.row(2);
  A.row(1) = Q0.row(1) - x0.y() * Q0.row(2);
  A.row(2) = Q1.row(0) - x1.x() * Q1.row(2);
  A.row(3) = Q1.row(1) - x1.y() * Q1.row(2);
  for (int r = 0; r < 4; ++r) {
    const double n = A.row(r).norm();
    if (!(n > 0) || !std::isfinite(n)) {
      out.status = Rejection::kDegenerate;
      return out;
    }
    A.row(r) /= n;
  }
  const Eigen::JacobiSVD<Eigen::Matrix4d> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d sv = svd.singularValues();  // descending
  // A unique solution needs rank 3: a second (near-)zero singular value means a whole
  // pencil of solutions, e.g. two identical rays.
  if (!(sv(2) > 1e-10 * sv(0))) {
    out.status = Rejection::kDegenerate;
    return out;
  }
  const Eigen::Vector4d v = svd.matrixV().col(3);
  // |w| tiny against the direction part: the point lies more than ~1e9 baselines away.
  if (!(std::abs(v(3)) > 1e-9 * v.head<3>().norm())) {
    out.status = Rejection::kAtInfinity;
    return out;
  }
  out.X = S.topRightCorner<3, 1>() + baseline * v.head<3>() / v(3);
  if (!out.X.allFinite()) {
    out.X.setZero();
    out.status = Rejection::kDegenerate;
  }
  return out;
}

TriangulatedPoint triangulate(const Camera& cam0, const Camera& cam1, const Correspondence& m,
                              const TriangulationOptions& opts) {
  const ProjectionPair g{cam0.projectionMatrix(), cam1.projectionMatrix()};
  return triangulateWith(cam0, cam1, g, m, opts);
}

std::vector<TriangulatedPoint> triangulateAll(const Camera& cam0, const Camera& cam1,
                                              std::span<const Correspondence> matches,
                                              const TriangulationOptions& opts) {
  const ProjectionPair g{cam0.projectionMatrix(), cam1.projectionMatrix()};
  std::vector<TriangulatedPoint> out(matches.size());
  // Each result goes to its own slot: no reduction, so the output is independent of
  // how TBB splits the range.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, matches.size(), 256),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      const FloatEnvGuard fenv;  // geometry/float_env.h
                      for (std::size_t i = r.begin(); i != r.end(); ++i)
                        out[i] = triangulateWith(cam0, cam1, g, matches[i], opts);
                    });
  return out;
}

}  // namespace saresgs
