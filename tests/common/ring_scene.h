#pragma once
// The smallest scene every kind of test builds on: six cameras on a ring. Kept apart from
// test_support.h (which needs GoogleTest) so that the fuzz targets, built without it, share
// the same cameras as the tests whose checkpoints seed them.
#include <cmath>
#include <functional>
#include <string>

#include "geometry/scene/scene.h"

namespace saresgs::test {

// Six 16x12 pinhole cameras on a ring of radius 3 at height 0.5, looking at the origin:
// the scene of the checkpoints committed as fuzz regression inputs. `name(i)` names view
// i; view 0 is the test view when `first_is_test`, else every view trains.
inline Scene ringScene(const std::function<std::string(int)>& name, bool first_is_test) {
  Scene s;
  Intrinsics K;
  K.width = 16;
  K.height = 12;
  K.fx = K.fy = 14;
  K.cx = 8;
  K.cy = 6;
  for (int i = 0; i < 6; ++i) {
    SceneView v;
    v.name = name(i);
    const double a = 2 * M_PI * i / 6;
    v.camera = Camera::lookAt(K, Eigen::Vector3d(3 * std::cos(a), 3 * std::sin(a), 0.5), Eigen::Vector3d::Zero());
    s.views.push_back(v);
    (first_is_test && i == 0 ? s.test : s.train).push_back(i);
  }
  s.finalize();
  return s;
}

}  // namespace saresgs::test
