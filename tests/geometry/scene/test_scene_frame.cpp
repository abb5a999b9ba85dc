// The frame a loaded scene is computed in (geometry/scene/scene_frame.h): which frame is
// chosen, that cameras, points and depth maps move into it consistently, and its JSON.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/test_support.h"
#include "geometry/error.h"
#include "geometry/io/pfm.h"
#include "geometry/scene/scene.h"
#include "geometry/scene/scene_frame.h"
#include "geometry/synth/synthetic_scene.h"

using namespace saresgs;

namespace {

TEST(SceneFrame, ChoosesAPowerOfTenBelowTheExtentAndARoundCentre) {
  const Eigen::Vector3d o = Eigen::Vector3d::Zero();
  // Metres about the origin: kept (the range the defaults were made for).
  EXPECT_TRUE(chooseSceneFrame(1.0, o).identity());
  EXPECT_TRUE(chooseSceneFrame(9.99, Eigen::Vector3d(4.9, -4.9, 0)).identity());
  // Another decade: the power of ten at or below the extent.
  EXPECT_EQ(chooseSceneFrame(0.5, o).scale, 0.1);
  EXPECT_EQ(chooseSceneFrame(12.0, o).scale, 10.0);
  EXPECT_EQ(chooseSceneFrame(3.3e3, o).scale, 1e3);
  EXPECT_EQ(chooseSceneFrame(3.3e-3, o).scale, std::pow(10.0, -3.0));
  // The centre: the mean rounded to a multiple of 10 x scale.
  EXPECT_EQ(chooseSceneFrame(3.0, Eigen::Vector3d(7, -12, 4)).center, Eigen::Vector3d(10, -10, 0));
  EXPECT_EQ(chooseSceneFrame(3.0, Eigen::Vector3d(1e6 + 2.5, -5e4 - 1, 0)).center, Eigen::Vector3d(1e6, -5e4, 0));
  EXPECT_EQ(chooseSceneFrame(3e3, Eigen::Vector3d(1e6 + 2.5e3, 0, 0)).center, Eigen::Vector3d(1e6, 0, 0));
  // A centre that rounds to zero from below is 0, not -0 (it is printed and written).
  const SceneFrame mm = chooseSceneFrame(3e3, Eigen::Vector3d(-20, -4e3, 0));
  EXPECT_FALSE(std::signbit(mm.center.x()));
  EXPECT_FALSE(std::signbit(mm.center.y()));
  // Nothing to measure: the identity.
  EXPECT_TRUE(chooseSceneFrame(0.0, o).identity());
  EXPECT_TRUE(chooseSceneFrame(std::numeric_limits<double>::infinity(), o).identity());
  EXPECT_TRUE(chooseSceneFrame(std::nan(""), o).identity());
  EXPECT_TRUE(chooseSceneFrame(2.0, Eigen::Vector3d(std::nan(""), 0, 0)).identity());
}

TEST(SceneFrame, CamerasProjectTheSameInBothFrames) {
  SceneFrame f;
  f.center = Eigen::Vector3d(4e5, -3e5, 120);
  f.scale = 1e3;
  Intrinsics K{640, 480, 500, 520, 300, 250};
  const Eigen::Vector3d eye = f.center + Eigen::Vector3d(2500, -1200, 800);
  const Camera world = Camera::lookAt(K, eye, f.center, Eigen::Vector3d::UnitZ());
  const Camera internal = f.toInternal(world);
  EXPECT_LT((internal.center() - f.toInternal(eye)).norm(), 1e-9);
  EXPECT_LT((f.toWorld(internal).t - world.t).norm(), 1e-9 * world.t.norm());
  for (const Eigen::Vector3d& x :
       {Eigen::Vector3d(f.center), Eigen::Vector3d(f.center + Eigen::Vector3d(300, 200, -100))}) {
    const auto a = world.project(x), b = internal.project(f.toInternal(x));
    ASSERT_TRUE(a && b);
    EXPECT_LT((*a - *b).norm(), 1e-6);
    // Depth along the camera axis scales with the frame.
    EXPECT_NEAR(world.toCamera(x).z() / f.scale, internal.toCamera(f.toInternal(x)).z(), 1e-9);
  }
}

// A scene in world coordinates, far away and in millimetres, moved into its frame.
TEST(SceneFrame, MoveToOwnFrameMovesCamerasPointsAndDepth) {
  test::TempDir d;
  Scene s;
  s.source = "mm";
  Intrinsics K{8, 6, 8, 8, 4, 3};
  const Eigen::Vector3d origin(2e6, 3e6, 0);
  for (int i = 0; i < 4; ++i) {
    SceneView v;
    v.name = "v" + std::to_string(i);
    v.camera = Camera::lookAt(K, origin + 4000.0 * Eigen::Vector3d(std::cos(1.5 * i), std::sin(1.5 * i), 0.25), origin);
    s.views.push_back(v);
    s.train.push_back(i);
  }
  ImageF depth(8, 6, 1, 4000.0f);
  writePfm(d.file("d.pfm"), depth);
  s.views[0].depth_path = d.file("d.pfm");
  s.points.push_back({origin + Eigen::Vector3d(100, -200, 50), {1, 2, 3}});
  s.finalize();
  const double world_extent = s.extent;
  moveToOwnFrame(s);
  EXPECT_EQ(s.frame.scale, 1e3);
  EXPECT_EQ(s.frame.center, origin);
  EXPECT_NEAR(s.extent, world_extent / 1e3, 1e-12 * world_extent);
  EXPECT_LT((s.points[0].xyz - Eigen::Vector3d(0.1, -0.2, 0.05)).norm(), 1e-9);
  EXPECT_LT((s.views[0].camera.center() - 4.0 * Eigen::Vector3d(1, 0, 0.25)).norm(), 1e-9);
  EXPECT_TRUE(s.aabb.min.isApprox(s.points[0].xyz));
  EXPECT_FLOAT_EQ(s.depth(0).at(3, 2), 4.0f);
  // Twice is a mistake of the caller's.
  EXPECT_THROW(moveToOwnFrame(s), std::logic_error);
}

// Every capture `saresgs scene` makes is in metres about the origin, so its frame is the
// identity and its numbers are those of the versions before the frame, bit for bit (the
// verdict grids pair runs across versions).
TEST(SceneFrame, TheBuiltInCapturesKeepTheirWorldFrame) {
  for (const char* layout : {"object", "room360", "unbalanced", "tworooms", "corridor"})
    for (std::uint64_t seed : {0u, 1u, 100u}) {
      SyntheticOptions o;
      o.layout = layout;
      o.seed = seed;
      o.width = 16;
      o.height = 12;
      const SyntheticScene s = makeSyntheticScene(o);
      std::vector<Camera> train;
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (int i : s.train) {
        train.push_back(s.cameras[static_cast<std::size_t>(i)]);
        mean += train.back().center();
      }
      mean /= static_cast<double>(train.size());
      const double extent = sceneExtent(train);
      EXPECT_TRUE(chooseSceneFrame(extent, mean).identity())
          << layout << " seed " << seed << ": extent " << extent << ", centre " << mean.transpose();
    }
}

TEST(SceneFrame, JsonRoundTripAndErrorsNameTheField) {
  SceneFrame f;
  f.center = Eigen::Vector3d(1e6, -2.5, 0.125);
  f.scale = 1e-3;
  EXPECT_EQ(sceneFrameFromJson(toJson(f), "r.json", "frame"), f);
  nlohmann::json bad = toJson(f);
  bad["scale"] = -1;
  EXPECT_TRUE(test::throwsInputError([&] { sceneFrameFromJson(bad, "r.json", "frame"); }, "r.json", "frame.scale"));
  bad = toJson(f);
  bad["center"] = {1, 2};
  EXPECT_TRUE(test::throwsInputError([&] { sceneFrameFromJson(bad, "r.json", "frame"); }, "r.json", "frame.center"));
  EXPECT_TRUE(
      test::throwsInputError([&] { sceneFrameFromJson(nlohmann::json(3), "r.json", "frame"); }, "r.json", "frame"));
}

}  // namespace
