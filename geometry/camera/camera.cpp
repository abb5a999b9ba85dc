#include "geometry/camera/camera.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "geometry/error.h"

namespace saresgs {

Eigen::Matrix3d Intrinsics::matrix() const {
  Eigen::Matrix3d k;
  k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
  return k;
}

double Intrinsics::fovX() const { return 2.0 * std::atan(0.5 * width / fx); }
double Intrinsics::fovY() const { return 2.0 * std::atan(0.5 * height / fy); }

Intrinsics Intrinsics::scaled(double factor) const {
  Intrinsics s;
  s.width = static_cast<int>(std::lround(width * factor));
  s.height = static_cast<int>(std::lround(height * factor));
  // Scale about the image corner: pixel edges stay pixel edges.
  const double sx = static_cast<double>(s.width) / width;
  const double sy = static_cast<double>(s.height) / height;
  s.fx = fx * sx;
  s.fy = fy * sy;
  s.cx = cx * sx;
  s.cy = cy * sy;
  return s;
}

bool Intrinsics::valid() const {
  return width > 0 && height > 0 && width <= kMaxImageSide && height <= kMaxImageSide && std::isfinite(fx) &&
         std::isfinite(fy) && fx > 0 && fy > 0 && std::isfinite(cx) && std::isfinite(cy);
}

Camera Camera::fromQuaternion(const Intrinsics& K, const Eigen::Quaterniond& q, const Eigen::Vector3d& t) {
  Camera c;
  c.K = K;
  c.R = q.normalized().toRotationMatrix();
  c.t = t;
  return c;
}

Camera Camera::lookAt(const Intrinsics& K, const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                      const Eigen::Vector3d& up) {
  Eigen::Vector3d z = (target - eye).normalized();
  Eigen::Vector3d u = up.normalized();
  if (std::abs(z.dot(u)) > 0.999) {
    // Looking straight along `up`: any perpendicular vector will do.
    u = std::abs(z.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  }
  // Image y points down: the camera's y axis is -up made perpendicular to z;
  // x = y cross z keeps the frame right-handed (x cross y = z).
  const Eigen::Vector3d y = (-u - (-u).dot(z) * z).normalized();
  const Eigen::Vector3d x = y.cross(z);
  Camera c;
  c.K = K;
  c.R.row(0) = x.transpose();
  c.R.row(1) = y.transpose();
  c.R.row(2) = z.transpose();
  c.t = -c.R * eye;
  return c;
}

Eigen::Quaterniond Camera::quaternion() const {
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0) q.coeffs() *= -1.0;
  return q;
}

Eigen::Vector3d Camera::center() const { return -R.transpose() * t; }

Eigen::Vector3d Camera::viewDirection() const { return R.row(2).transpose(); }

Eigen::Matrix<double, 3, 4> Camera::projectionMatrix() const {
  Eigen::Matrix<double, 3, 4> rt;
  rt.leftCols<3>() = R;
  rt.col(3) = t;
  return K.matrix() * rt;
}

std::optional<Eigen::Vector2d> Camera::project(const Eigen::Vector3d& x_world, double min_depth) const {
  const Eigen::Vector3d p = toCamera(x_world);
  if (!(p.z() > min_depth)) return std::nullopt;
  return Eigen::Vector2d(K.fx * p.x() / p.z() + K.cx, K.fy * p.y() / p.z() + K.cy);
}

Eigen::Vector3d Camera::unproject(const Eigen::Vector2d& uv, double z) const {
  const Eigen::Vector3d p((uv.x() - K.cx) / K.fx * z, (uv.y() - K.cy) / K.fy * z, z);
  return toWorld(p);
}

Eigen::Vector3d Camera::rayDirection(const Eigen::Vector2d& uv) const {
  const Eigen::Vector3d d((uv.x() - K.cx) / K.fx, (uv.y() - K.cy) / K.fy, 1.0);
  return (R.transpose() * d).normalized();
}

std::array<Plane, 6> Camera::frustumPlanes(double near, double far) const {
  // Build the planes in camera coordinates, then move them to world coordinates.
  // Side planes pass through the centre and the image edges (u = 0, u = W, v = 0, v = H).
  auto side = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& inside) {
    Eigen::Vector3d n = a.cross(b).normalized();
    if (n.dot(inside) < 0) n = -n;
    return n;
  };
  const double l = (0 - K.cx) / K.fx, r = (K.width - K.cx) / K.fx;
  const double tp = (0 - K.cy) / K.fy, bt = (K.height - K.cy) / K.fy;
  const Eigen::Vector3d inside((l + r) / 2, (tp + bt) / 2, 1.0);
  const Eigen::Vector3d tl(l, tp, 1), tr(r, tp, 1), bl(l, bt, 1), br(r, bt, 1);
  std::array<Eigen::Vector3d, 6> n_cam = {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, -1), side(tl, bl, inside),
                                          side(tr, br, inside),     side(tl, tr, inside),      side(bl, br, inside)};
  std::array<double, 6> d_cam = {-near, far, 0, 0, 0, 0};
  std::array<Plane, 6> planes;
  for (int i = 0; i < 6; ++i) {
    // n_c . (R x + t) + d_c = (R^T n_c) . x + (n_c . t + d_c)
    planes[i].n = R.transpose() * n_cam[i];
    planes[i].d = n_cam[i].dot(t) + d_cam[i];
  }
  return planes;
}

bool Camera::inFrustum(const Eigen::Vector3d& x_world, double near, double far) const {
  const Eigen::Vector3d p = toCamera(x_world);
  if (!(p.z() >= near && p.z() <= far) || p.z() <= 0) return false;
  const auto uv = project(x_world);
  return uv && uv->x() >= 0 && uv->y() >= 0 && uv->x() <= K.width && uv->y() <= K.height;
}

double sceneExtent(std::span<const Camera> cameras) {
  if (cameras.empty()) return 0.0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& c : cameras) mean += c.center();
  mean /= static_cast<double>(cameras.size());
  double r = 0;
  for (const auto& c : cameras) r = std::max(r, (c.center() - mean).norm());
  return 1.1 * r;
}

ViewFocus viewFocus(std::span<const Camera> cameras) {
  ViewFocus f;
  if (cameras.empty()) return f;
  const double n = static_cast<double>(cameras.size());
  Eigen::Vector3d mean_c = Eigen::Vector3d::Zero(), mean_d = Eigen::Vector3d::Zero();
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const Camera& c : cameras) {
    // The squared distance of p from the axis c + s d is |(I - d d^T)(p - c)|^2.
    const Eigen::Vector3d d = c.viewDirection().normalized();
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - d * d.transpose();
    A += P;
    b += P * c.center();
    mean_c += c.center();
    mean_d += d;
  }
  mean_c /= n;
  mean_d /= n;
  double spread = 0;
  for (const Camera& c : cameras) spread = std::max(spread, (c.center() - mean_c).norm());
  auto medianOf = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  auto halfTan = [](const Camera& c) { return std::tan(0.5 * std::min(c.K.fovX(), c.K.fovY())); };

  // A's eigenvalues are n times the mean squared sine of the angles between the axes and
  // each eigenvector; the smallest is about n sin^2(spread of the view directions). Below
  // about 3 degrees of spread the intersection is set by noise in the poses.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(A);
  const double min_sin2 = std::pow(std::sin(3.0 * M_PI / 180.0), 2);
  if (eig.eigenvalues()[0] > min_sin2 * n) {
    const Eigen::Vector3d p = A.ldlt().solve(b);
    std::vector<double> depth, radius;
    for (const Camera& c : cameras) {
      depth.push_back(c.viewDirection().normalized().dot(p - c.center()));
      radius.push_back((p - c.center()).norm() * halfTan(c));
    }
    if (p.allFinite() && medianOf(depth) > 0) {
      f.center = p;
      f.radius = medianOf(radius);
      f.axes_meet = true;
      return f;
    }
  }
  if (mean_d.norm() < 0.5) {  // cameras facing every way: around their centres
    f.center = mean_c;
    f.radius = spread > 0 ? 2 * spread : 1.0;
    return f;
  }
  const double depth = spread > 0 ? ViewFocus::kFallbackDepth * spread : 1.0;
  f.center = mean_c + depth * mean_d.normalized();
  std::vector<double> half;
  for (const Camera& c : cameras) half.push_back(halfTan(c));
  f.radius = depth * medianOf(half) + spread;
  return f;
}

void validateCamera(const Camera& cam, const std::string& file, const std::string& field) {
  if (!cam.K.valid()) {
    std::ostringstream s;
    s << "expected positive finite focal lengths and an image size of 1.." << kMaxImageSide
      << " per side, got fx=" << cam.K.fx << " fy=" << cam.K.fy << " size=" << cam.K.width << "x" << cam.K.height;
    throw InputError(file, field, s.str());
  }
  if (!cam.R.allFinite() || !cam.t.allFinite()) throw InputError(file, field, "expected a finite pose, got NaN or Inf");
  const double orth = (cam.R * cam.R.transpose() - Eigen::Matrix3d::Identity()).norm();
  if (orth > 1e-6 || std::abs(cam.R.determinant() - 1.0) > 1e-6)
    throw InputError(file, field, "expected a rotation (orthonormal, det +1)");
}

}  // namespace saresgs
