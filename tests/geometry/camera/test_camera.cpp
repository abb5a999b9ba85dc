#include <gtest/gtest.h>

#include <random>

#include "geometry/camera/camera.h"
#include "geometry/error.h"

using namespace saresgs;

namespace {

Intrinsics makeK(int w = 256, int h = 192) {
  return Intrinsics{.width = w, .height = h, .fx = 220, .fy = 230, .cx = 0.5 * w + 3.25, .cy = 0.5 * h - 2.5};
}

Camera randomCamera(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0, 1);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  return Camera::fromQuaternion(makeK(), q.normalized(), Eigen::Vector3d(n(rng), n(rng), n(rng)));
}

}  // namespace

TEST(Camera, ProjectUnprojectAreInverse) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(0, 1);
  for (int k = 0; k < 50; ++k) {
    const Camera c = randomCamera(rng);
    for (int j = 0; j < 20; ++j) {
      const Eigen::Vector2d uv(u(rng) * c.K.width, u(rng) * c.K.height);
      const double z = 0.01 + 100 * u(rng);
      const Eigen::Vector3d X = c.unproject(uv, z);
      const auto back = c.project(X);
      ASSERT_TRUE(back.has_value());
      EXPECT_NEAR((*back - uv).norm(), 0.0, 1e-8);
      EXPECT_NEAR(c.toCamera(X).z(), z, 1e-9 * (1 + z));
      // The ray direction through uv points at X from the centre.
      const Eigen::Vector3d d = (X - c.center()).normalized();
      EXPECT_NEAR((d - c.rayDirection(uv)).norm(), 0.0, 1e-9);
    }
  }
}

TEST(Camera, PointsBehindTheCameraDoNotProject) {
  const Camera c = Camera::fromQuaternion(makeK(), Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero());
  EXPECT_FALSE(c.project(Eigen::Vector3d(0, 0, -1)).has_value());
  EXPECT_FALSE(c.project(Eigen::Vector3d(1, 1, 0)).has_value());
  EXPECT_TRUE(c.project(Eigen::Vector3d(0, 0, 1)).has_value());
}

TEST(Camera, PrincipalPointIsTheViewDirection) {
  std::mt19937_64 rng(2);
  const Camera c = randomCamera(rng);
  const Eigen::Vector3d X = c.center() + 5.0 * c.viewDirection();
  const auto uv = c.project(X);
  ASSERT_TRUE(uv);
  EXPECT_NEAR(uv->x(), c.K.cx, 1e-9);
  EXPECT_NEAR(uv->y(), c.K.cy, 1e-9);
}

TEST(Camera, FrustumPlanesHoldExactlyThePointsThatProjectInside) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  const double near = 0.5, far = 20.0;
  int inside = 0, outside = 0;
  for (int k = 0; k < 20; ++k) {
    const Camera c = randomCamera(rng);
    const auto planes = c.frustumPlanes(near, far);
    for (int j = 0; j < 2000; ++j) {
      // Points around the frustum, in camera coordinates, then to world.
      const Eigen::Vector3d pc(u(rng) * 25, u(rng) * 25, u(rng) * 25);
      const Eigen::Vector3d X = c.toWorld(pc);
      bool by_planes = true;
      for (const auto& p : planes) by_planes = by_planes && p.signedDistance(X) >= 0;
      bool by_projection = false;
      if (pc.z() >= near && pc.z() <= far) {
        const auto uv = c.project(X);
        by_projection = uv && uv->x() >= 0 && uv->x() <= c.K.width && uv->y() >= 0 && uv->y() <= c.K.height;
      }
      // Points within 1e-9 of a plane may go either way.
      double margin = 1e300;
      for (const auto& p : planes) margin = std::min(margin, std::abs(p.signedDistance(X)));
      if (margin < 1e-9) continue;
      EXPECT_EQ(by_planes, by_projection) << "point " << pc.transpose();
      EXPECT_EQ(c.inFrustum(X, near, far), by_projection);
      (by_projection ? inside : outside)++;
    }
  }
  EXPECT_GT(inside, 500);  // the sample exercises both sides
  EXPECT_GT(outside, 500);
}

TEST(Camera, LookAtLooksAtTargetWithImageUpAlongUp) {
  const Camera c =
      Camera::lookAt(makeK(), Eigen::Vector3d(3, 0, 1), Eigen::Vector3d(0, 0, 1), Eigen::Vector3d::UnitZ());
  EXPECT_NEAR((c.viewDirection() - Eigen::Vector3d(-1, 0, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR(c.R.determinant(), 1.0, 1e-12);
  // A point above the target appears above the principal point (smaller v).
  const auto uv = c.project(Eigen::Vector3d(0, 0, 2));
  ASSERT_TRUE(uv);
  EXPECT_LT(uv->y(), c.K.cy);
  // Degenerate up (parallel to the view) still gives a rotation, not NaN.
  const Camera d = Camera::lookAt(makeK(), Eigen::Vector3d(0, 0, 5), Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ());
  EXPECT_TRUE(d.R.allFinite());
  EXPECT_NEAR(d.R.determinant(), 1.0, 1e-12);
}

TEST(Camera, QuaternionRoundTrip) {
  std::mt19937_64 rng(4);
  for (int k = 0; k < 100; ++k) {
    const Camera c = randomCamera(rng);
    const Camera d = Camera::fromQuaternion(c.K, c.quaternion(), c.t);
    EXPECT_NEAR((c.R - d.R).norm(), 0, 1e-12);
    EXPECT_GE(c.quaternion().w(), 0);
  }
}

TEST(Camera, ExtentFollows3DGS) {
  std::vector<Camera> cams(4);
  const Eigen::Vector3d centers[4] = {{1, 0, 0}, {-1, 0, 0}, {0, 2, 0}, {0, -2, 0}};
  for (int i = 0; i < 4; ++i) {
    cams[i].K = makeK();
    cams[i].t = -centers[i];  // R = I, so centre = -t
  }
  EXPECT_NEAR(sceneExtent(cams), 1.1 * 2.0, 1e-12);
  EXPECT_EQ(sceneExtent({}), 0.0);
}

TEST(Camera, ScaledIntrinsicsKeepPixelEdges) {
  const Intrinsics K = makeK(256, 192);
  const Intrinsics h = K.scaled(0.5);
  EXPECT_EQ(h.width, 128);
  EXPECT_EQ(h.height, 96);
  EXPECT_DOUBLE_EQ(h.cx, K.cx * 0.5);
  EXPECT_DOUBLE_EQ(h.fx, K.fx * 0.5);
}

TEST(Camera, ValidationNamesFileAndField) {
  Camera c;
  c.K = makeK();
  EXPECT_NO_THROW(validateCamera(c, "cams.txt", "camera 1"));
  c.K.fx = -3;
  try {
    validateCamera(c, "cams.txt", "camera 1");
    FAIL() << "negative focal length accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cams.txt"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("camera 1"), std::string::npos);
  }
  c.K = makeK();
  c.t.x() = std::nan("");
  EXPECT_THROW(validateCamera(c, "f", "g"), InputError);
  c.t.setZero();
  c.R(0, 0) = 2;
  EXPECT_THROW(validateCamera(c, "f", "g"), InputError);
}

// viewFocus: where cameras without points look.
namespace {

std::vector<Camera> hemisphere(const Eigen::Vector3d& target, double radius, int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Camera> cams;
  for (int i = 0; i < n; ++i) {
    const double phi = 2 * M_PI * u(rng), z = 0.1 + 0.85 * u(rng), r = std::sqrt(1 - z * z);
    cams.push_back(
        Camera::lookAt(makeK(), target + radius * Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z), target));
  }
  return cams;
}

}  // namespace

TEST(ViewFocus, CamerasOnAHemisphereLookAtTheirTarget) {
  // Object-centred capture away from the origin (the mean of the centres is well above it).
  const Eigen::Vector3d target(1.5, -2.0, 0.75);
  const std::vector<Camera> cams = hemisphere(target, 4.0, 40, 7);
  const ViewFocus f = viewFocus(cams);
  EXPECT_TRUE(f.axes_meet);
  EXPECT_NEAR((f.center - target).norm(), 0.0, 1e-9);
  // Every camera is 4 from the target: the radius is 4 tan(half the narrower fov).
  EXPECT_NEAR(f.radius, 4.0 * std::tan(0.5 * std::min(makeK().fovX(), makeK().fovY())), 1e-9);
  // The mean of the camera centres, the old init's centre, is far from the target.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Camera& c : cams) mean += c.center();
  mean /= static_cast<double>(cams.size());
  EXPECT_GT((mean - target).norm(), f.radius);
}

TEST(ViewFocus, InwardFacingRingWithNoisyAxesFindsTheCentre) {
  // A ring at varying heights looking at points scattered about the centre: the least-
  // squares point stays near the centre and in front of every camera.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0, 0.1);
  std::vector<Camera> cams;
  for (int i = 0; i < 36; ++i) {
    const double a = 2 * M_PI * i / 36;
    const Eigen::Vector3d eye(3 * std::cos(a), 3 * std::sin(a), 0.5 + 0.3 * std::sin(3 * a));
    cams.push_back(Camera::lookAt(makeK(), eye, Eigen::Vector3d(noise(rng), noise(rng), noise(rng))));
  }
  const ViewFocus f = viewFocus(cams);
  EXPECT_TRUE(f.axes_meet);
  EXPECT_LT(f.center.norm(), 0.15);
  for (const Camera& c : cams) EXPECT_GT(c.toCamera(f.center).z(), 0);
  EXPECT_GT(f.radius, 0.5);
  EXPECT_LT(f.radius, 3.0);
}

TEST(ViewFocus, ParallelAxesFallBackToADepthAlongTheViewDirection) {
  // Forward-facing capture: a 3x3 grid of cameras, all looking along +y.
  std::vector<Camera> cams;
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j) {
      const Eigen::Vector3d eye(0.1 * i, 0, 0.1 * j);
      cams.push_back(Camera::lookAt(makeK(), eye, eye + Eigen::Vector3d(0, 1, 0)));
    }
  const ViewFocus f = viewFocus(cams);
  EXPECT_FALSE(f.axes_meet);
  const double spread = 0.1 * std::sqrt(2.0);
  EXPECT_NEAR(f.center.x(), 0.0, 1e-12);
  EXPECT_NEAR(f.center.z(), 0.0, 1e-12);
  EXPECT_NEAR(f.center.y(), ViewFocus::kFallbackDepth * spread, 1e-9);
  for (const Camera& c : cams) EXPECT_TRUE(c.project(f.center).has_value());
  EXPECT_GT(f.radius, spread);

  // Outward-facing cameras (their axes meet behind them): the centres' mean.
  std::vector<Camera> out;
  for (int i = 0; i < 8; ++i) {
    const double a = 2 * M_PI * i / 8;
    const Eigen::Vector3d eye(0.2 * std::cos(a), 0.2 * std::sin(a), 0);
    out.push_back(Camera::lookAt(makeK(), eye, 2 * eye));
  }
  const ViewFocus g = viewFocus(out);
  EXPECT_FALSE(g.axes_meet);
  EXPECT_LT(g.center.norm(), 1e-12);
  EXPECT_NEAR(g.radius, 0.4, 1e-9);
  // One camera: a point in front of it.
  const ViewFocus one = viewFocus(std::span<const Camera>(cams.data(), 1));
  EXPECT_FALSE(one.axes_meet);
  EXPECT_GT(cams[0].toCamera(one.center).z(), 0);
}
