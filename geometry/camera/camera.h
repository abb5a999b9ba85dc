#pragma once
// Pinhole camera in the COLMAP/OpenCV convention: world-to-camera rotation R and
// translation t (x_cam = R x_world + t), x right, y down, z forward. Pixel (i, j)
// covers [i, i+1) x [j, j+1), so its centre is at (i + 0.5, j + 0.5).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <optional>
#include <span>
#include <vector>

namespace saresgs {

// The largest image side a dataset may declare (readers refuse more before allocating).
inline constexpr int kMaxImageSide = 65536;

struct Intrinsics {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;

  Eigen::Matrix3d matrix() const;
  // Horizontal / vertical field of view in radians.
  double fovX() const;
  double fovY() const;
  // The same camera for an image resized by `factor` (e.g. 0.5 for half size).
  Intrinsics scaled(double factor) const;
  // Positive finite focal lengths, finite principal point, size 1..kMaxImageSide.
  bool valid() const;
  bool operator==(const Intrinsics&) const = default;
};

// A plane n.x + d = 0 with unit normal n pointing to the inside of a volume.
struct Plane {
  Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  double d = 0;
  double signedDistance(const Eigen::Vector3d& x) const { return n.dot(x) + d; }
};

struct Camera {
  Intrinsics K;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // world -> camera
  Eigen::Vector3d t = Eigen::Vector3d::Zero();

  static Camera fromQuaternion(const Intrinsics& K, const Eigen::Quaterniond& q_wxyz, const Eigen::Vector3d& t);
  // A camera at `eye` looking at `target`, with image "up" (-y) as close to `up` as
  // possible. Falls back to another up vector when `up` is parallel to the view.
  static Camera lookAt(const Intrinsics& K, const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                       const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

  Eigen::Quaterniond quaternion() const;                 // world -> camera, normalised, w >= 0
  Eigen::Vector3d center() const;                        // camera centre in world coordinates
  Eigen::Vector3d viewDirection() const;                 // +z axis of the camera in world coordinates
  Eigen::Matrix<double, 3, 4> projectionMatrix() const;  // K [R | t]

  Eigen::Vector3d toCamera(const Eigen::Vector3d& x_world) const { return R * x_world + t; }
  Eigen::Vector3d toWorld(const Eigen::Vector3d& x_cam) const { return R.transpose() * (x_cam - t); }

  // Projects a world point to continuous pixel coordinates. Returns nothing for points
  // at or behind the camera plane (z <= min_depth).
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& x_world, double min_depth = 1e-12) const;
  // The world point at pixel coordinates `uv` and depth `z` along the camera's z axis
  // (the convention of COLMAP and of 3DGS depth maps).
  Eigen::Vector3d unproject(const Eigen::Vector2d& uv, double z) const;
  // Unit ray direction in world coordinates through pixel coordinates `uv`.
  Eigen::Vector3d rayDirection(const Eigen::Vector2d& uv) const;

  bool inImage(const Eigen::Vector2d& uv) const {
    return uv.x() >= 0 && uv.y() >= 0 && uv.x() < K.width && uv.y() < K.height;
  }
  // Six inward planes: near, far, left, right, top, bottom.
  std::array<Plane, 6> frustumPlanes(double near, double far) const;
  // True when the point projects inside the image and near <= z <= far.
  bool inFrustum(const Eigen::Vector3d& x_world, double near, double far) const;
};

// The 3DGS scene scale: 1.1 x the largest distance of the camera centres from their mean.
double sceneExtent(std::span<const Camera> cameras);

// Where a set of cameras looks, for a dataset without points: `center` is the point
// closest in least squares to the cameras' optical axes, `radius` the half-size of the
// volume they see about it (the median over cameras of distance x tan(half the narrower
// field of view): a view-filling object about the centre). When the axes are near-parallel
// (forward-facing captures) or their closest point lies behind most cameras, the axes do
// not meet (`axes_meet` false) and `center` is instead at a typical depth along the mean
// view direction (kFallbackDepth x the cameras' spread, or 1 when they share one centre),
// with the radius from that depth plus the spread; cameras facing every way (outward)
// get their mean centre and twice their spread.
struct ViewFocus {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0;
  bool axes_meet = false;
  static constexpr double kFallbackDepth = 4.0;
};
ViewFocus viewFocus(std::span<const Camera> cameras);

// Throws InputError(file, field, ...) when R is not a rotation, t is not finite or the
// intrinsics are not positive and finite.
void validateCamera(const Camera& cam, const std::string& file, const std::string& field);

}  // namespace saresgs
