#include <gtest/gtest.h>

#include <filesystem>

#include "common/synthetic_options.h"
#include "common/test_support.h"
#include "geometry/error.h"
#include "geometry/io/colmap.h"
#include "geometry/scene/scene.h"
#include "geometry/synth/synthetic_scene.h"
#include "geometry/synth/write_dataset.h"

using namespace saresgs;
using saresgs::test::TempDir;
namespace fs = std::filesystem;

namespace {

// A small COLMAP dataset: `n` images of 32x24 on a circle, a few points.
ColmapModel writeDataset(const TempDir& d, int n, const std::string& model = "PINHOLE", bool binary = false) {
  ColmapModel m;
  ColmapCamera c;
  c.id = 3;
  c.model = model;
  c.width = 32;
  c.height = 24;
  c.params = model == "SIMPLE_PINHOLE" ? std::vector<double>{30, 16, 12}
             : model == "PINHOLE"      ? std::vector<double>{30, 31, 16, 12}
                                       : std::vector<double>{30, 31, 16, 12, 0.1, 0.01, 0, 0};
  m.cameras[c.id] = c;
  fs::create_directories(d.path() / "images");
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    const Camera cam = Camera::lookAt(Intrinsics{32, 24, 30, 31, 16, 12},
                                      Eigen::Vector3d(3 * std::cos(a), 3 * std::sin(a), 1), Eigen::Vector3d::Zero());
    ColmapImage im;
    im.id = 100 + (n - i);  // ids in the opposite order of names: sorting is by name
    im.q = cam.quaternion();
    im.t = cam.t;
    im.camera_id = c.id;
    im.name = "img_" + std::to_string(1000 + i) + ".png";
    m.images[im.id] = im;
    writeImage(d.file("images/" + im.name), Image8(32, 24, 3, static_cast<std::uint8_t>(i * 10)));
  }
  for (int k = 0; k < 5; ++k) {
    ColmapPoint3D p;
    p.id = 7 + k;
    p.xyz = Eigen::Vector3d(0.1 * k, -0.2 * k, 0.05 * k);
    p.rgb = {static_cast<std::uint8_t>(k), 2, 3};
    m.points[p.id] = p;
  }
  if (binary)
    writeColmapBinary(d.file("sparse/0"), m);
  else
    writeColmapText(d.file("sparse/0"), m);
  return m;
}

}  // namespace

TEST(ColmapDataset, LoadsCamerasSortedByNameWithEveryEighthATestView) {
  for (bool binary : {false, true}) {
    TempDir d;
    const ColmapModel m = writeDataset(d, 17, "PINHOLE", binary);
    const Scene s = loadDataset(d.str());
    ASSERT_EQ(s.views.size(), 17u);
    EXPECT_EQ(s.test, (std::vector<int>{0, 8, 16}));
    EXPECT_EQ(s.train.size(), 14u);
    for (size_t i = 0; i < s.views.size(); ++i) {
      EXPECT_EQ(s.views[i].name, "img_" + std::to_string(1000 + i) + ".png");
      const ColmapImage& im = m.images.at(static_cast<std::uint32_t>(100 + 17 - i));
      EXPECT_EQ(s.views[i].camera.t, im.t);
      EXPECT_NEAR((s.views[i].camera.R - im.q.toRotationMatrix()).norm(), 0, 1e-15);
      EXPECT_EQ(s.views[i].camera.K.fy, 31);
    }
    EXPECT_EQ(s.points.size(), 5u);
    EXPECT_EQ(s.points[2].xyz, Eigen::Vector3d(0.2, -0.4, 0.1));
    EXPECT_EQ(s.aabb.max.x(), 0.4);
    EXPECT_EQ(s.image(3).at(0, 0, 1), 30);  // the 4th name's image
  }
}

TEST(ColmapDataset, TestEveryIsConfigurable) {
  TempDir d;
  writeDataset(d, 10);
  DatasetOptions o;
  o.test_every = 0;
  EXPECT_TRUE(loadDataset(d.str(), o).test.empty());
  o.test_every = 3;
  EXPECT_EQ(loadDataset(d.str(), o).test, (std::vector<int>{0, 3, 6, 9}));
}

TEST(ColmapDataset, SimplePinholeHasEqualFocalLengths) {
  TempDir d;
  writeDataset(d, 3, "SIMPLE_PINHOLE");
  const Scene s = loadDataset(d.str());
  EXPECT_EQ(s.views[0].camera.K.fx, 30);
  EXPECT_EQ(s.views[0].camera.K.fy, 30);
}

TEST(ColmapDataset, DistortedModelsAskForUndistortion) {
  TempDir d;
  writeDataset(d, 3, "OPENCV");
  EXPECT_TRUE(test::throwsInputError([&] { loadDataset(d.str()); }, "cameras.txt", "image_undistorter"));
}

TEST(ColmapDataset, DownscaledFolderIsPreferredAndResizingIsTheFallback) {
  TempDir d;
  writeDataset(d, 3);
  DatasetOptions o;
  o.load.downscale = 2;
  {
    const Scene s = loadDataset(d.str(), o);  // no images_2: resized on load
    EXPECT_EQ(s.views[0].camera.K.width, 16);
    EXPECT_EQ(s.views[0].camera.K.fx, 15);
    EXPECT_EQ(s.image(1).width, 16);
    EXPECT_EQ(s.image(1).at(0, 0, 0), 10);
  }
  fs::create_directories(d.path() / "images_2");
  for (int i = 0; i < 3; ++i)
    writeImage(d.file("images_2/img_" + std::to_string(1000 + i) + ".png"), Image8(16, 12, 3, 77));
  const Scene s = loadDataset(d.str(), o);
  EXPECT_NE(s.views[0].image_path.find("images_2"), std::string::npos);
  EXPECT_EQ(s.image(1).at(0, 0, 0), 77);
}

TEST(ColmapDataset, MissingImageNamesTheFile) {
  TempDir d;
  writeDataset(d, 4);
  fs::remove(d.path() / "images" / "img_1002.png");
  EXPECT_TRUE(test::throwsInputError([&] { loadDataset(d.str()); }, "img_1002.png", "missing"));
}

TEST(ColmapDataset, MismatchedImageSizeNamesTheFile) {
  TempDir d;
  writeDataset(d, 4);
  writeImage(d.file("images/img_1001.png"), Image8(40, 24, 3, 0));
  const Scene s = loadDataset(d.str());
  EXPECT_TRUE(test::throwsInputError([&] { s.image(1); }, "img_1001.png", "image size"));
}

TEST(ColmapDataset, NonPositiveFocalLengthIsRefused) {
  TempDir d;
  ColmapModel m = writeDataset(d, 3);
  m.cameras.begin()->second.params[0] = 0;
  writeColmapText(d.file("sparse/0"), m);
  EXPECT_TRUE(test::throwsInputError([&] { loadDataset(d.str()); }, "cameras.txt", "focal length"));
}

TEST(ColmapDataset, MissingModelSaysWhatWasExpected) {
  TempDir d;
  fs::create_directories(d.path() / "images");
  EXPECT_TRUE(test::throwsInputError([&] { loadDataset(d.str()); }, d.str(), "sparse model"));
  EXPECT_TRUE(test::throwsInputError([&] { loadDataset(d.file("nope")); }, "nope", "dataset"));
}

TEST(ColmapDataset, ManifestSplitWinsOverTheEveryEighthRule) {
  TempDir d;
  writeDataset(d, 6);
  test::writeBytes(
      d.file("manifest.json"),
      R"({"split": {"train": ["img_1000.png", "img_1002.png", "img_1003.png", "img_1004.png", "img_1005.png"], "test": ["img_1001.png"]}})");
  const Scene s = loadDataset(d.str());
  EXPECT_EQ(s.test, (std::vector<int>{1}));
  EXPECT_EQ(s.train, (std::vector<int>{0, 2, 3, 4, 5}));
  test::writeBytes(d.file("manifest.json"), R"({"split": {"train": ["nope.png"], "test": []}})");
  EXPECT_TRUE(test::throwsInputError([&] { loadDataset(d.str()); }, "manifest.json", "split.train"));
}

// manifest.json: wrong types and sizes name the field; a name twice in the split or in
// both parts, and sizes or counts that disagree with the model, are errors.
TEST(ColmapDataset, ManifestFieldsAreTypedBoundedAndMatchTheModel) {
  TempDir d;
  writeDataset(d, 6);
  const std::string train =
      R"("train": ["img_1000.png", "img_1002.png", "img_1003.png", "img_1004.png", "img_1005.png"])";
  struct Case {
    std::string manifest, field;
  };
  for (const Case& c : std::vector<Case>{
           {R"({"split": [1, 2]})", "split: expected an object"},
           {R"({"split": {"train": "img_1000.png"}})", "split.train: expected an array"},
           {R"({"split": {"train": ["img_1000.png", 3]}})", "split.train[1]: expected a string"},
           {R"({"split": {"train": ["img_1000.png", "img_1000.png"]}})", "split.train"},
           {"{\"split\": {" + train + R"(, "test": ["img_1001.png", "img_1002.png"]}})", "split.test"},
           {R"({"width": "abc"})", "width: expected a whole number"},
           {R"({"width": 64})", "width"},
           {R"({"height": 24.5})", "height: expected a whole number"},
           {R"({"num_views": 2e9})", "num_views: expected a whole number in 1..100000"},
           {R"({"num_views": 7})", "num_views"},
           {R"({"background": [1, "white", 1]})", "background[1]"},
           {R"({"background": 5})", "background"},
           {R"([1, 2])", "json"},
       }) {
    test::writeBytes(d.file("manifest.json"), c.manifest);
    std::string msg;
    try {
      loadDataset(d.str());
    } catch (const InputError& e) {
      msg = e.what();
    }
    EXPECT_NE(msg.find("manifest.json"), std::string::npos) << c.manifest << ": " << msg;
    EXPECT_NE(msg.find(c.field), std::string::npos) << c.manifest << ": " << msg;
    EXPECT_EQ(msg.find("json.exception"), std::string::npos) << msg;
  }
  // The sizes the model has are accepted.
  test::writeBytes(d.file("manifest.json"), R"({"width": 32, "height": 24, "num_views": 6, "background": null})");
  EXPECT_FALSE(loadDataset(d.str()).background.has_value());
}

TEST(ColmapDataset, AnImageNamedTwiceOrAWidthThatWrapsIsRefused) {
  TempDir d;
  ColmapModel m = writeDataset(d, 3);
  m.images.begin()->second.name = std::next(m.images.begin())->second.name;
  writeColmapText(d.file("sparse/0"), m);
  EXPECT_TRUE(test::throwsInputError([&] { loadDataset(d.str()); }, "images.txt", "appears twice"));
  // 2^32 + 64 must not wrap to 64 (which would match the images).
  TempDir e;
  writeDataset(e, 3);
  std::string cams = test::readBytes(e.file("sparse/0/cameras.txt"));
  const auto at = cams.find("PINHOLE 32 ");
  ASSERT_NE(at, std::string::npos);
  cams.replace(at, 11, "PINHOLE 4294967328 ");
  test::writeBytes(e.file("sparse/0/cameras.txt"), cams);
  EXPECT_TRUE(test::throwsInputError([&] { loadDataset(e.str()); }, "cameras.txt", "width"));
}

// Found with the manifest fuzz target (fuzz/fuzz_manifest.cpp): a manifest whose "split"
// is an array, not {train, test}, escaped as nlohmann's "cannot use value() with array".
TEST(ColmapDataset, AManifestSplitThatIsNotAnObjectNamesTheField) {
  TempDir d;
  WriteDatasetOptions w;
  w.simulated.max_points = 6;
  w.simulated.candidates = 400;
  writeSyntheticDataset(makeSyntheticScene(test::syntheticOptions("object", 16, 12, /*seed=*/0, /*num_views=*/4)),
                        d.file("ds"), w);
  ASSERT_NO_THROW(loadDataset(d.file("ds")));
  const std::string manifest = d.file("ds/manifest.json");
  test::writeBytes(manifest,
                   test::readBytes(test::fuzzRegression("geometry/scene/fuzz_regressions/manifest/split_array.json")));
  EXPECT_TRUE(test::throwsInputError([&] { loadDataset(d.file("ds")); }, manifest, "split"));
}
