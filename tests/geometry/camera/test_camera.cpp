#include <gtest/gtest.h>

#include <random>

#include "geometry/camera/camera.h"
#include "geometry/error.h"

using namespace saresgs;

namespace {

Intrinsics makeK(int w = 256, int h = 192) {
  Intrinsics K;
  K.width = w;
  K.height = h;
  K.fx = 220;
  K.fy = 230;
  K.cx = 0.5 * w + 3.25;
  K.cy = 0.5 * h - 2.5;
  return K;
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
        by_projection = uv && uv->x() >= 0 && uv->x() <= c.K.width && uv->y() >= 0 &&
                        uv->y() <= c.K.height;
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
  const Camera c = Camera::lookAt(makeK(), Eigen::Vector3d(3, 0, 1), Eigen::Vector3d(0, 0, 1),
                                  Eigen::Vector3d::UnitZ());
  EXPECT_NEAR((c.viewDirection() - Eigen::Vector3d(-1, 0, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR(c.R.determinant(), 1.0, 1e-12);
  // A point above the target appears above the principal point (smaller v).
  const auto uv = c.project(Eigen::Vector3d(0, 0, 2));
  ASSERT_TRUE(uv);
  EXPECT_LT(uv->y(), c.K.cy);
  // Degenerate up (parallel to the view) still gives a rotation, not NaN.
  const Camera d = Camera::lookAt(makeK(), Eigen::Vector3d(0, 0, 5), Eigen::Vector3d::Zero(),
                                  Eigen::Vector3d::UnitZ());
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
