#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <fstream>

#include "common/gl_pose.h"
#include "common/test_support.h"
#include "geometry/error.h"
#include "geometry/image/image.h"
#include "geometry/io/point_ply.h"
#include "geometry/scene/scene.h"

using namespace saresgs;
using nlohmann::json;
using saresgs::test::glPose;
using saresgs::test::TempDir;

namespace {

// n frames named frame_00001.jpg ... (JPEG, 40x30) with top-level intrinsics.
json writeFolder(const TempDir& d, int n) {
  std::filesystem::create_directories(d.path() / "images");
  json j = {{"fl_x", 50.0},
            {"fl_y", 52.0},
            {"cx", 19.0},
            {"cy", 16.0},
            {"w", 40},
            {"h", 30},
            {"camera_model", "OPENCV"},
            {"k1", 0.0},
            {"k2", 0.0},
            {"p1", 0.0},
            {"p2", 0.0},
            {"frames", json::array()}};
  for (int i = 0; i < n; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "images/frame_%05d.jpg", i + 1);
    const double a = 0.5 * i;
    j["frames"].push_back(
        {{"file_path", name}, {"transform_matrix", glPose(Eigen::Vector3d(4 * std::cos(a), 4 * std::sin(a), 1))}});
    Image8 img(40, 30, 3);
    for (auto& v : img.data) v = static_cast<std::uint8_t>(40 + 10 * i);
    writeImage(d.file(name), img);
  }
  return j;
}

void save(const TempDir& d, const json& j) { std::ofstream(d.file("transforms.json")) << j.dump(2); }

}  // namespace

TEST(NerfstudioDataset, IntrinsicsPerFileOrFrameAndEveryEighthViewByNameIsATestView) {
  TempDir d;
  json j = writeFolder(d, 17);
  // One frame overrides the file's focal length; the frames are listed out of order.
  j["frames"][3]["fl_x"] = 60.0;
  std::swap(j["frames"][0], j["frames"][16]);
  save(d, j);
  const Scene s = loadDataset(d.str());
  ASSERT_EQ(s.views.size(), 17u);
  // Sorted by name, views 0, 8 and 16 (frame_00001, 00009, 00017) are the test views.
  std::vector<std::string> test;
  for (int i : s.test) test.push_back(s.views[i].name);
  std::sort(test.begin(), test.end());
  EXPECT_EQ(test, (std::vector<std::string>{"frame_00001.jpg", "frame_00009.jpg", "frame_00017.jpg"}));
  EXPECT_EQ(s.train.size(), 14u);
  for (std::size_t i = 0; i < s.views.size(); ++i) {
    const Intrinsics& K = s.views[i].camera.K;
    EXPECT_EQ(K.fx, i == 3 ? 60.0 : 50.0) << i;
    EXPECT_EQ(K.fy, 52.0);
    EXPECT_EQ(K.cx, 19.0);
    EXPECT_EQ(K.width, 40);
    // OpenGL poses: the camera looks at the origin.
    EXPECT_NEAR(s.views[i].camera.viewDirection().dot(-s.views[i].camera.center().normalized()), 1.0, 1e-9);
  }
  EXPECT_EQ(s.image(0).width, 40);  // JPEG read
  EXPECT_TRUE(s.points.empty());
  EXPECT_FALSE(s.background.has_value());
}

TEST(NerfstudioDataset, PlyFilePathGivesThePointsAndFilenamesGiveTheSplit) {
  TempDir d;
  json j = writeFolder(d, 6);
  writePointsPly(d.file("sparse_pc.ply"),
                 {{Eigen::Vector3d(0.1, 0.2, 0.3), {10, 20, 30}}, {Eigen::Vector3d(-1, 0, 1), {1, 2, 3}}});
  j["ply_file_path"] = "sparse_pc.ply";
  j["train_filenames"] = {"images/frame_00002.jpg", "images/frame_00003.jpg", "images/frame_00005.jpg"};
  j["val_filenames"] = {"images/frame_00006.jpg"};
  save(d, j);
  const Scene s = loadDataset(d.str());
  ASSERT_EQ(s.points.size(), 2u);
  EXPECT_EQ(s.points[1].rgb, (std::array<std::uint8_t, 3>{1, 2, 3}));
  EXPECT_EQ(s.train, (std::vector<int>{1, 2, 4}));
  EXPECT_EQ(s.test, (std::vector<int>{5}));
}

TEST(NerfstudioDataset, DistortionFisheyesAndBadFieldsAreRefusedByField) {
  const std::vector<std::pair<std::function<void(json&)>, std::string>> cases = {
      {[](json& j) { j["k1"] = 0.013; }, "k1"},
      {[](json& j) { j["frames"][2]["p2"] = -0.001; }, "frames[2].p2"},
      {[](json& j) { j["camera_model"] = "OPENCV_FISHEYE"; }, "camera_model"},
      {[](json& j) { j["frames"][1]["camera_model"] = "EQUIRECTANGULAR"; }, "frames[1].camera_model"},
      {[](json& j) { j["ply_file_path"] = "nowhere.ply"; }, "ply_file_path"},
      {[](json& j) {
         j["applied_transform"] =
             json::array({json::array({1, 0, 0}), json::array({0, 1, 0, 0}), json::array({0, 0, 1, 0})});
       },
       "applied_transform[0]"},
      {[](json& j) { j["train_filenames"] = {"images/frame_00001.jpg"}; }, "test_filenames"},
      {[](json& j) {
         j["train_filenames"] = {"images/frame_00001.jpg", "images/nope.jpg"};
         j["test_filenames"] = {"images/frame_00002.jpg"};
       },
       "train_filenames[1]"},
      {[](json& j) { j["fl_x"] = -5.0; }, "intrinsics"},
  };
  for (const auto& [edit, field] : cases) {
    TempDir d;
    json j = writeFolder(d, 4);
    edit(j);
    save(d, j);
    EXPECT_TRUE(test::throwsInputError([&] { loadDataset(d.str()); }, d.file("transforms.json"), field)) << field;
  }
  // Zero distortion of OPENCV and SIMPLE_RADIAL is a pinhole camera: accepted.
  TempDir d;
  json j = writeFolder(d, 4);
  j["camera_model"] = "SIMPLE_RADIAL";
  save(d, j);
  EXPECT_EQ(loadDataset(d.str()).views.size(), 4u);
}
