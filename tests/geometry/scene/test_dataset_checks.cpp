#include <gtest/gtest.h>

#include <cmath>

#include "common/test_support.h"
#include "geometry/error.h"
#include "geometry/scene/dataset_checks.h"

using namespace saresgs;

namespace {

// The 320x240 camera of every view, with focal length f and principal point (cx, cy).
Intrinsics withFocal(double f, double cx = 160, double cy = 120) {
  return Intrinsics{.width = 320, .height = 240, .fx = f, .fy = f, .cx = cx, .cy = cy};
}

// Four views on a ring looking at a cloud of points about the origin; view 1 may get
// other intrinsics.
Scene ring(const Intrinsics& odd) {
  Scene s;
  s.source = "ring";
  const Intrinsics K = withFocal(300);
  for (int i = 0; i < 4; ++i) {
    SceneView v;
    v.name = "v" + std::to_string(i) + ".jpg";
    v.camera = Camera::lookAt(i == 1 ? odd : K, Eigen::Vector3d(4 * std::cos(1.5 * i), 4 * std::sin(1.5 * i), 1),
                              Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ());
    s.views.push_back(v);
    (i == 3 ? s.test : s.train).push_back(i);
  }
  for (int k = 0; k < 50; ++k)
    s.points.push_back({Eigen::Vector3d(0.02 * k - 0.5, 0.3 * std::sin(k), 0.2 * std::cos(k)), {1, 2, 3}});
  return s;
}

}  // namespace

TEST(DatasetChecks, PlausibleCamerasGiveNoWarning) {
  EXPECT_TRUE(checkDataset(ring(withFocal(300))).empty());
  // 2 degrees across 320 px is a lens people use.
  EXPECT_TRUE(checkDataset(ring(withFocal(160 / std::tan(M_PI / 180)))).empty());
}

TEST(DatasetChecks, ImplausibleIntrinsicsAreNamedWithTheirView) {
  // 0.001 px: a field of view of 180 degrees less a hair, and nothing projects inside.
  auto w = checkDataset(ring(withFocal(0.001)));
  ASSERT_GE(w.size(), 2u);
  EXPECT_EQ(w[0].view, "v1.jpg");
  EXPECT_EQ(w[0].field, "fx");
  EXPECT_NE(w[0].message.find("field of view"), std::string::npos) << w[0].message;
  // 1e9 px: 2e-5 degrees.
  w = checkDataset(ring(withFocal(1e9)));
  ASSERT_GE(w.size(), 2u);
  EXPECT_EQ(w[0].field, "fx");
  EXPECT_EQ(w[1].field, "fy");
  // A principal point at (5000, -3000) for a 320x240 image: both named, and the view
  // sees none of the points.
  w = checkDataset(ring(withFocal(300, 5000, -3000)));
  ASSERT_EQ(w.size(), 3u);
  EXPECT_EQ(w[0].field, "cx");
  EXPECT_EQ(w[1].field, "cy");
  EXPECT_EQ(w[2].field, "points");
  EXPECT_EQ(w[2].view, "v1.jpg");
  const std::string text = formatWarnings(w, 2);
  EXPECT_NE(text.find("warning: v1.jpg: cx: "), std::string::npos) << text;
  EXPECT_NE(text.find("and 1 more"), std::string::npos) << text;
}

TEST(DatasetChecks, NoTrainViewSeeingAnyPointIsRefused) {
  Scene s = ring(withFocal(300));
  for (auto& p : s.points) p.xyz = Eigen::Vector3d(0, 0, 100);  // straight above every camera
  EXPECT_TRUE(test::throwsInputError([&] { checkDataset(s); }, "ring", "intrinsics or poses"));
  // Without points there is nothing to check against.
  s.points.clear();
  EXPECT_TRUE(checkDataset(s).empty());
}

// The frame (issue 25): the same ring moved 1e6 from the origin, or shrunk a thousandfold,
// trains badly and silently without these warnings; scaled up a thousandfold it is fine.
TEST(DatasetChecks, AFrameFarFromTheOriginOrTooSmallIsNamed) {
  auto moved = [](double scale, const Eigen::Vector3d& shift) {
    Scene s = ring(withFocal(300));
    for (SceneView& v : s.views)
      v.camera = Camera::lookAt(v.camera.K, scale * v.camera.center() + shift, shift, Eigen::Vector3d::UnitZ());
    for (SparsePoint& p : s.points) p.xyz = scale * p.xyz + shift;
    return s;
  };
  EXPECT_TRUE(checkDataset(moved(1.0, Eigen::Vector3d::Zero())).empty());
  EXPECT_TRUE(checkDataset(moved(1e3, Eigen::Vector3d::Zero())).empty());
  EXPECT_TRUE(checkDataset(moved(1.0, Eigen::Vector3d(300, 0, 0))).empty());  // 75x the spread: fine

  auto far = checkDataset(moved(1.0, Eigen::Vector3d(1e6, 1e6, 0)));
  ASSERT_EQ(far.size(), 1u);
  EXPECT_EQ(far[0].view, "(scene)");
  EXPECT_EQ(far[0].field, "frame");
  EXPECT_NE(far[0].message.find("recentre"), std::string::npos) << far[0].message;

  auto small = checkDataset(moved(1e-3, Eigen::Vector3d::Zero()));
  ASSERT_EQ(small.size(), 1u);
  EXPECT_EQ(small[0].field, "scale");
  EXPECT_NE(small[0].message.find("near plane (0.01)"), std::string::npos) << small[0].message;
  // The renderer's near plane is the caller's.
  EXPECT_TRUE(checkDataset(moved(1e-3, Eigen::Vector3d::Zero()), 1e-6).empty());
}
