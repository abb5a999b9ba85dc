#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>

#include "common/gl_pose.h"
#include "common/test_support.h"
#include "geometry/error.h"
#include "geometry/image/image.h"
#include "geometry/scene/scene.h"

using namespace saresgs;
using nlohmann::json;
using saresgs::test::glPose;
using saresgs::test::TempDir;

namespace {

// A camera-to-world matrix in OpenGL axes: camera at `eye` looking at the origin.
void writeRgba(const std::string& path, int w, int h, std::uint8_t alpha) {
  Image8 img(w, h, 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      img.at(x, y, 0) = 200;
      img.at(x, y, 1) = 100;
      img.at(x, y, 2) = 0;
      img.at(x, y, 3) = alpha;
    }
  writeImage(path, img);
}

void writeSplit(const TempDir& d, const std::string& name, const std::string& sub, int n,
                double angle = 0.6911112070083618) {
  json j;
  j["camera_angle_x"] = angle;
  j["frames"] = json::array();
  std::filesystem::create_directories(d.path() / sub);
  for (int i = 0; i < n; ++i) {
    const double a = 0.7 * i;
    j["frames"].push_back({{"file_path", "./" + sub + "/r_" + std::to_string(i)},
                           {"transform_matrix", glPose(Eigen::Vector3d(4 * std::cos(a), 4 * std::sin(a), 1.5))}});
    writeRgba(d.file(sub + "/r_" + std::to_string(i) + ".png"), 40, 30, 128);
  }
  std::ofstream(d.file(name)) << j.dump(2);
}

}  // namespace

TEST(BlenderDataset, ConvertsOpenGLPosesToOpenCV) {
  TempDir d;
  writeSplit(d, "transforms_train.json", "train", 5);
  writeSplit(d, "transforms_test.json", "test", 2);
  DatasetOptions opts;
  opts.background = BackgroundChoice{false, {0.0f, 0.0f, 1.0f}};
  const Scene s = loadDataset(d.str(), opts);
  ASSERT_EQ(s.views.size(), 7u);
  EXPECT_EQ(s.train.size(), 5u);
  EXPECT_EQ(s.test.size(), 2u);
  for (const auto& v : s.views) {
    // OpenCV +z looks at the origin, image y points down (world z up).
    EXPECT_NEAR(v.camera.viewDirection().dot(-v.camera.center().normalized()), 1.0, 1e-9);
    const auto uv = v.camera.project(Eigen::Vector3d(0, 0, 0));
    ASSERT_TRUE(uv);
    EXPECT_NEAR(uv->x(), 20.0, 1e-9);
    EXPECT_NEAR(uv->y(), 15.0, 1e-9);
    const auto above = v.camera.project(Eigen::Vector3d(0, 0, 0.5));
    EXPECT_LT(above->y(), uv->y());
    EXPECT_NEAR(v.camera.K.fx, 0.5 * 40 / std::tan(0.5 * 0.6911112070083618), 1e-9);
  }
  // RGBA composited on the background: alpha 128 of (200,100,0) over (0,0,255).
  const Image8& img = s.image(0);
  ASSERT_EQ(img.channels, 3);
  EXPECT_NEAR(img.at(3, 3, 0), 200 * 128 / 255.0, 1.0);
  EXPECT_NEAR(img.at(3, 3, 2), 255 * (1 - 128 / 255.0), 1.0);
  EXPECT_GT(s.extent, 0.0);
}

TEST(BlenderDataset, DownscaleResizesOnLoad) {
  TempDir d;
  writeSplit(d, "transforms_train.json", "train", 2);
  DatasetOptions opts;
  opts.load.downscale = 2;
  const Scene s = loadDataset(d.str(), opts);
  EXPECT_EQ(s.views[0].camera.K.width, 20);
  EXPECT_EQ(s.image(0).width, 20);
  EXPECT_EQ(s.image(0).height, 15);
}

TEST(BlenderDataset, ErrorsNameFileAndField) {
  auto expectError = [](const std::string& dir, const std::string& file_part, const std::string& field) {
    EXPECT_TRUE(test::throwsInputError([&] { loadDataset(dir); }, file_part, field));
  };
  {
    TempDir d;
    writeSplit(d, "transforms_train.json", "train", 2);
    std::filesystem::remove(d.file("train/r_1.png"));
    expectError(d.str(), "r_1", "frames[1].file_path");
  }
  {
    TempDir d;
    writeSplit(d, "transforms_train.json", "train", 2, -1.0);
    expectError(d.str(), "transforms_train.json", "camera_angle_x");
  }
  {
    TempDir d;
    writeSplit(d, "transforms_train.json", "train", 1);
    std::ofstream(d.file("transforms_train.json")) << "{\"camera_angle_x\": 0.7, \"frames\": [";
    expectError(d.str(), "transforms_train.json", "json");
  }
  {
    TempDir d;
    writeSplit(d, "transforms_train.json", "train", 1);
    json j = json::parse(std::ifstream(d.file("transforms_train.json")));
    j["frames"][0]["transform_matrix"][0][3] = std::nan("");  // json writes NaN as null
    std::ofstream(d.file("transforms_train.json")) << j.dump();
    expectError(d.str(), "transforms_train.json", "transform_matrix");
  }
}

// Wrong JSON types name the file and the field (not nlohmann's "type must be number");
// sizes are bounded; an image listed twice, in one split or in both, is refused.
TEST(BlenderDataset, MistypedFieldsRepeatsAndSizesAreRefusedByField) {
  auto edited = [](const std::function<void(json&, json&)>& edit) {
    auto d = std::make_unique<TempDir>();
    writeSplit(*d, "transforms_train.json", "train", 3);
    writeSplit(*d, "transforms_test.json", "test", 2);
    json train = json::parse(std::ifstream(d->file("transforms_train.json")));
    json test = json::parse(std::ifstream(d->file("transforms_test.json")));
    edit(train, test);
    std::ofstream(d->file("transforms_train.json")) << train.dump();
    std::ofstream(d->file("transforms_test.json")) << test.dump();
    return d;
  };
  struct Case {
    std::function<void(json&, json&)> edit;
    std::string file, field;
  };
  const std::vector<Case> cases{
      {[](json& t, json&) { t["camera_angle_x"] = "wide"; }, "transforms_train.json",
       "camera_angle_x: expected a number"},
      {[](json& t, json&) { t["frames"] = json::object(); }, "transforms_train.json", "frames: expected an array"},
      {[](json& t, json&) {
         t["frames"][1] = json::array({1, 2});
       },
       "transforms_train.json", "frames[1]: expected an object"},
      {[](json& t, json&) { t["frames"][1]["file_path"] = 7; }, "transforms_train.json",
       "frames[1].file_path: expected a string"},
      {[](json& t, json&) { t["frames"][2]["transform_matrix"][1][2] = "x"; }, "transforms_train.json",
       "frames[2].transform_matrix[1][2]: expected a number"},
      {[](json& t, json&) { t["frames"][0]["transform_matrix"] = 3; }, "transforms_train.json",
       "frames[0].transform_matrix"},
      {[](json&, json& s) { s["frames"][0]["cx"] = json::array(); }, "transforms_test.json",
       "frames[0].cx: expected a number"},
      {[](json& t, json&) {
         t["w"] = "40";
         t["h"] = 30;
       },
       "transforms_train.json", "w: expected a whole number"},
      {[](json& t, json&) {
         t["w"] = 4294967336.0;
         t["h"] = 30;
       },
       "transforms_train.json", "w: expected a whole number in 1..65536"},
      {[](json& t, json&) { t["frames"][2]["file_path"] = "./train/r_0"; }, "transforms_train.json",
       "frames[2].file_path"},
      {[](json& t, json& s) { s["frames"][1]["file_path"] = t["frames"][0]["file_path"]; }, "transforms_test.json",
       "frames[1].file_path"},
  };
  for (const Case& c : cases) {
    const auto d = edited(c.edit);
    std::string msg;
    try {
      loadDataset(d->str());
    } catch (const InputError& e) {
      msg = e.what();
    }
    EXPECT_NE(msg.find(c.file), std::string::npos) << c.field << ": " << msg;
    EXPECT_NE(msg.find(c.field), std::string::npos) << msg;
    EXPECT_EQ(msg.find("json.exception"), std::string::npos) << msg;
  }
  // The repeat names where the image was first listed.
  const auto d = edited([](json& t, json& s) { s["frames"][1]["file_path"] = t["frames"][0]["file_path"]; });
  EXPECT_TRUE(
      test::throwsInputError([&] { loadDataset(d->str()); }, "listed twice", "transforms_train.json frames[0]"));
}

// A manifest beside the transforms (`saresgs scene --format blender`) must agree with the
// cameras; "background": null means the data has none.
TEST(BlenderDataset, ManifestSizesMustMatchAndNullMeansNoBackground) {
  TempDir d;
  writeSplit(d, "transforms_train.json", "train", 3);
  test::writeBytes(d.file("manifest.json"), R"({"width": 40, "height": 30, "num_views": 3, "background": null})");
  const Scene s = loadDataset(d.str());
  EXPECT_FALSE(s.background.has_value());
  test::writeBytes(d.file("manifest.json"), R"({"width": 64, "height": 30, "num_views": 3})");
  EXPECT_TRUE(test::throwsInputError([&] { loadDataset(d.str()); }, "manifest.json", "width"));
  test::writeBytes(d.file("manifest.json"), R"({"num_views": 4})");
  EXPECT_TRUE(test::throwsInputError([&] { loadDataset(d.str()); }, "manifest.json", "num_views"));
  test::writeBytes(d.file("manifest.json"), R"({"num_views": 2e9})");
  EXPECT_TRUE(test::throwsInputError([&] { loadDataset(d.str()); }, "manifest.json",
                                     "num_views: expected a whole number in 1..100000"));
  // With --downscale the manifest is compared with the full-size cameras.
  test::writeBytes(d.file("manifest.json"), R"({"width": 40, "height": 30})");
  DatasetOptions half;
  half.load.downscale = 2;
  EXPECT_EQ(loadDataset(d.str(), half).views[0].camera.K.width, 20);
}

// Found with the Blender fuzz target (fuzz/fuzz_blender.cpp) on mutations of its
// Instant-NGP seed: a size or principal point of the wrong type escaped as nlohmann's
// "type must be number", and a size of 1e30 was converted to int (undefined behaviour).
TEST(BlenderDataset, SizesAndCentresOfTheWrongTypeOrRangeNameTheirField) {
  TempDir d;
  for (int i = 0; i < 4; ++i) writeImage(d.file("r_" + std::to_string(i) + ".png"), Image8(8, 6, 4, 200));
  const std::string file = d.file("transforms_train.json");
  for (const auto& [input, field] : std::vector<std::pair<std::string, std::string>>{
           {"w_string.json", "w"}, {"w_1e30.json", "w"}, {"cx_string.json", "cx"}}) {
    test::writeBytes(file, test::readBytes(test::fuzzRegression("geometry/scene/fuzz_regressions/blender/" + input)));
    EXPECT_TRUE(test::throwsInputError([&] { loadBlenderDataset(d.str()); }, file, field)) << input;
  }
}

// Preloading decodes several images at once: each view gets the image image() would have
// read, and of several unreadable images the error names the first in the order asked,
// whichever decode finished first.
TEST(BlenderDataset, PreloadReadsWhatImageReadsAndNamesTheFirstBadViewAsked) {
  TempDir d;
  writeSplit(d, "transforms_train.json", "train", 6);
  for (int i = 0; i < 6; ++i)
    writeRgba(d.file("train/r_" + std::to_string(i) + ".png"), 40, 30, static_cast<std::uint8_t>(30 * i + 10));
  const Scene one_by_one = loadDataset(d.str());
  const Scene preloaded = loadDataset(d.str());
  std::vector<int> all(preloaded.views.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  EXPECT_EQ(preloaded.preloadImages({5, 1, 3, 1}), 3u);     // repeats, out of order, some views first
  EXPECT_EQ(preloaded.preloadImages(all), all.size() - 3);  // the kept ones are not read again
  for (int v : all) {
    EXPECT_EQ(preloaded.image(v).data, one_by_one.image(v).data) << "view " << v;
    EXPECT_EQ(preloaded.image(v).width, 40);
  }
  // Distinct images, so the comparison above would see a view given another's image.
  EXPECT_NE(one_by_one.image(0).data, one_by_one.image(1).data);

  const Scene broken = loadDataset(d.str());
  int v2 = -1, v4 = -1;
  for (std::size_t i = 0; i < broken.views.size(); ++i) {
    if (broken.views[i].image_path.find("r_2") != std::string::npos) v2 = static_cast<int>(i);
    if (broken.views[i].image_path.find("r_4") != std::string::npos) v4 = static_cast<int>(i);
  }
  ASSERT_GE(v2, 0);
  ASSERT_GE(v4, 0);
  test::writeBytes(d.file("train/r_2.png"), "not a png");
  test::writeBytes(d.file("train/r_4.png"), "not a png either");
  for (int round = 0; round < 5; ++round) {
    EXPECT_TRUE(test::throwsInputError([&] { broken.preloadImages({v4, 0, v2}); }, "r_4", "file"));
    EXPECT_TRUE(test::throwsInputError([&] { broken.preloadImages({v2, 0, v4}); }, "r_2", "file"));
  }
  // What did decode is kept; the bad ones stay unread.
  EXPECT_EQ(broken.image(0).data, one_by_one.image(0).data);
  EXPECT_TRUE(test::throwsInputError([&] { (void)broken.image(v2); }, "r_2", "file"));
}
