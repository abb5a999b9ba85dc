#pragma once
// The smallest scene every kind of test builds on: six cameras on a ring. Kept apart from
// test_support.h (which needs GoogleTest) so that the fuzz targets, built without it, share
// the same cameras as the tests whose checkpoints seed them.
#include <cmath>
#include <functional>
#include <string>

#include "geometry/scene/scene.h"
#include "tests/common/pinhole.h"

namespace saresgs::test {

// n cameras with intrinsics K evenly spaced on a ring of `radius` at `height` about the z
// axis (view i at angle 2 pi i / n), looking at the origin with +z up. `name(i)` names
// view i; view 0 is the test view when `first_is_test`, else every view trains. Not
// finalized: the caller adds points first, or keeps the scene's aabb and extent unset.
inline Scene cameraRing(int n, const Intrinsics& K, double radius, double height,
                        const std::function<std::string(int)>& name, bool first_is_test) {
  Scene s;
  for (int i = 0; i < n; ++i) {
    SceneView v;
    v.name = name(i);
    const double a = 2 * M_PI * i / n;
    v.camera =
        Camera::lookAt(K, Eigen::Vector3d(radius * std::cos(a), radius * std::sin(a), height), Eigen::Vector3d::Zero());
    s.views.push_back(v);
    (first_is_test && i == 0 ? s.test : s.train).push_back(i);
  }
  return s;
}

// Six 16x12 pinhole cameras on a ring of radius 3 at height 0.5, looking at the origin:
// the scene of the checkpoints committed as fuzz regression inputs. `name(i)` names view
// i; view 0 is the test view when `first_is_test`, else every view trains.
inline Scene ringScene(const std::function<std::string(int)>& name, bool first_is_test) {
  Scene s = cameraRing(6, pinhole(16, 12, 14), 3, 0.5, name, first_is_test);
  s.finalize();
  return s;
}

}  // namespace saresgs::test
