#include <gtest/gtest.h>

#include <cmath>

#include "geometry/scene/cameras_json.h"

using namespace saresgs;

// The 3DGS cameras.json convention: position is the camera centre and rotation the
// camera-to-world rotation, so that x_cam = rotation^T (x_world - position).
TEST(CamerasJson, PositionAndRotationMapTheWorldIntoEachCamera) {
  Scene s;
  const Intrinsics K{.width = 64, .height = 48, .fx = 70, .fy = 72, .cx = 31, .cy = 25};
  for (int i = 0; i < 3; ++i) {
    SceneView v;
    v.name = "img_" + std::to_string(i) + ".png";
    v.camera = Camera::lookAt(K, Eigen::Vector3d(3 * std::cos(i), 3 * std::sin(i), 1.0 + i),
                              Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Vector3d::UnitZ());
    s.views.push_back(v);
  }
  const nlohmann::json j = camerasJson(s);
  ASSERT_EQ(j.size(), 3u);
  const Eigen::Vector3d X(0.4, -0.7, 0.9);
  for (std::size_t i = 0; i < 3; ++i) {
    const Camera& c = s.views[i].camera;
    EXPECT_EQ(j[i]["id"], i);
    EXPECT_EQ(j[i]["img_name"], "img_" + std::to_string(i));
    EXPECT_EQ(j[i]["width"], 64);
    EXPECT_EQ(j[i]["height"], 48);
    EXPECT_EQ(j[i]["fx"], 70.0);
    EXPECT_EQ(j[i]["fy"], 72.0);
    Eigen::Vector3d p;
    Eigen::Matrix3d R;
    for (int r = 0; r < 3; ++r) {
      p[r] = j[i]["position"][r];
      for (int k = 0; k < 3; ++k) R(r, k) = j[i]["rotation"][r][k];
    }
    EXPECT_LT((p - c.center()).norm(), 1e-12);
    EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    EXPECT_LT((R.transpose() * (X - p) - c.toCamera(X)).norm(), 1e-12);
    // The third column is the viewing direction (OpenCV: z forward).
    EXPECT_LT((R.col(2) - c.viewDirection()).norm(), 1e-12);
  }
}
