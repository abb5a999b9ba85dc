#pragma once
// A camera-to-world transform_matrix in OpenGL axes (Blender's and nerfstudio's) for a
// camera at `eye` looking at the origin with world z up: the dataset tests' poses.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

namespace saresgs::test {

inline nlohmann::json glPose(const Eigen::Vector3d& eye) {
  const Eigen::Vector3d back = eye.normalized();  // OpenGL +z points away from the view
  const Eigen::Vector3d right = Eigen::Vector3d::UnitZ().cross(back).normalized();
  const Eigen::Vector3d up = back.cross(right);
  nlohmann::json m = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) m.push_back({right[r], up[r], back[r], eye[r]});
  m.push_back({0, 0, 0, 1});
  return m;
}

}  // namespace saresgs::test
