// The background rule (geometry/scene/background.h, settleBackground in scene.h): parsing
// `--background`, telling alpha from a file's header, and each loader's choice.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <fstream>

#include "common/gl_pose.h"
#include "common/test_support.h"
#include "geometry/error.h"
#include "geometry/image/image.h"
#include "geometry/scene/background.h"
#include "geometry/scene/scene.h"

using namespace saresgs;
using nlohmann::json;
using saresgs::test::glPose;
using saresgs::test::TempDir;

TEST(Background, ParsesTheNamedColoursRandomAndRgb) {
  EXPECT_EQ(parseBackground("white", "--background"), (BackgroundChoice{false, {1, 1, 1}}));
  EXPECT_EQ(parseBackground("black", "--background"), (BackgroundChoice{false, {0, 0, 0}}));
  EXPECT_EQ(parseBackground("random", "--background"), (BackgroundChoice{true, {1, 1, 1}}));
  EXPECT_EQ(parseBackground("0.25,0.5,1", "--background"), (BackgroundChoice{false, {0.25f, 0.5f, 1.0f}}));
  EXPECT_EQ(parseBackground("0,0,0", "--background"), (BackgroundChoice{false, {0, 0, 0}}));
  for (const char* text : {"white", "black", "random", "0.25,0.5,1"})
    EXPECT_EQ(parseBackground(backgroundText(parseBackground(text, "x")), "x"), parseBackground(text, "x")) << text;
}

TEST(Background, RefusesAnythingElseNamingTheOption) {
  for (const char* bad : {"", "White", "grey", "1,1", "1,1,1,1", "0.5,,0.5", "-0.1,0,0", "0,0,1.5", "nan,0,0",
                          "inf,0,0", "0x1,0,0 ", "1;1;1", "1, 1, 1x"}) {
    try {
      parseBackground(bad, "--background");
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), "--background");
      EXPECT_NE(std::string(e.what()).find("expected white, black, random, or R,G,B"), std::string::npos) << e.what();
    }
  }
}

TEST(Background, AlphaIsToldFromTheHeader) {
  TempDir d;
  Image8 rgb(5, 4, 3, 10), rgba(5, 4, 4, 200);
  writeImage(d.file("rgb.png"), rgb);
  writeImage(d.file("rgba.png"), rgba);
  writeImage(d.file("rgb.jpg"), rgb);
  EXPECT_FALSE(imageHasAlpha(d.file("rgb.png")));
  EXPECT_TRUE(imageHasAlpha(d.file("rgba.png")));
  EXPECT_FALSE(imageHasAlpha(d.file("rgb.jpg")));
  EXPECT_FALSE(imageHasAlpha(d.file("missing.png")));
  // A truncated or damaged file says no; reading it gives the error later.
  test::writeBytes(d.file("short.png"), std::string("\x89PNG\r\n\x1a\n\0\0", 10));
  EXPECT_FALSE(imageHasAlpha(d.file("short.png")));
  test::writeBytes(d.file("junk.png"), "not an image at all");
  EXPECT_FALSE(imageHasAlpha(d.file("junk.png")));
}

namespace {

// A nerfstudio folder of 4 views, 8x6, each pixel (200, 100, 0) with alpha `a` (RGB when
// a is 255 and `rgb`).
void writeNerfstudio(const TempDir& d, std::uint8_t a, bool rgb) {
  std::filesystem::create_directories(d.path() / "images");
  json j = {{"fl_x", 10.0}, {"fl_y", 10.0}, {"w", 8}, {"h", 6}, {"frames", json::array()}};
  for (int i = 0; i < 4; ++i) {
    const std::string name = "images/f" + std::to_string(i) + ".png";
    Image8 img(8, 6, rgb ? 3 : 4);
    for (int p = 0; p < 48; ++p) {
      img.data[img.channels * p] = 200;
      img.data[img.channels * p + 1] = 100;
      img.data[img.channels * p + 2] = 0;
      if (!rgb) img.data[4 * p + 3] = a;
    }
    writeImage(d.file(name), img);
    j["frames"].push_back(
        {{"file_path", name}, {"transform_matrix", glPose(Eigen::Vector3d(4 * std::cos(i), 4 * std::sin(i), 1))}});
  }
  std::ofstream(d.file("transforms.json")) << j.dump();
}

// The dataset in d loaded as `--background said` asks.
Scene loadWithBackground(const TempDir& d, const std::string& said) {
  DatasetOptions o;
  o.background = parseBackground(said, "--background");
  return loadDataset(d.str(), o);
}

}  // namespace

TEST(Background, NerfstudioRgbaIsCompositedOnWhiteAndTrainedOnWhite) {
  TempDir d;
  writeNerfstudio(d, 128, false);
  const Scene s = loadDataset(d.str());
  ASSERT_TRUE(s.background.has_value());
  EXPECT_EQ(*s.background, (std::array<float, 3>{1, 1, 1}));
  EXPECT_EQ(s.background_from, "alpha in the images, none said (white)");
  EXPECT_NE(backgroundWarning(s).find("the images have alpha but nothing says"), std::string::npos);
  // (200, 100, 0) at alpha 128 over white.
  const Image8& img = s.image(0);
  EXPECT_EQ(img.channels, 3);
  EXPECT_EQ(img.at(0, 0, 0), 227);
  EXPECT_EQ(img.at(0, 0, 1), 177);
  EXPECT_EQ(img.at(0, 0, 2), 127);
  EXPECT_EQ(s.alpha(0), nullptr);  // kept only for a random background
}

TEST(Background, ASaidColourWinsAndIsTheCompositingColour) {
  TempDir d;
  writeNerfstudio(d, 128, false);
  const Scene s = loadWithBackground(d, "0,0,1");
  EXPECT_EQ(*s.background, (std::array<float, 3>{0, 0, 1}));
  EXPECT_EQ(s.background_from, "--background");
  EXPECT_EQ(backgroundWarning(s), "");
  EXPECT_EQ(s.image(0).at(3, 2, 0), 100);  // 200 * 128/255
  EXPECT_EQ(s.image(0).at(3, 2, 2), 127);  // the blue behind

  // setBackground gives a copy another one; the copy reads its images again, the original
  // keeps its own.
  Scene black = s;
  setBackground(black, parseBackground("black", "x"));
  EXPECT_EQ(black.image(0).at(3, 2, 2), 0);
  EXPECT_EQ(s.image(0).at(3, 2, 2), 127);
}

TEST(Background, RandomKeepsEachImagesAlpha) {
  TempDir d;
  writeNerfstudio(d, 77, false);
  const Scene s = loadWithBackground(d, "random");
  EXPECT_TRUE(s.random_background);
  EXPECT_EQ(*s.background, (std::array<float, 3>{1, 1, 1}));  // what evaluation renders against
  const Image8* a = s.alpha(2);
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(a->channels, 1);
  EXPECT_EQ(a->width, 8);
  EXPECT_EQ(a->at(5, 5), 77);
}

TEST(Background, OpaqueImagesWithNothingSaidHaveNone) {
  TempDir d;
  writeNerfstudio(d, 255, true);
  const Scene s = loadDataset(d.str());
  EXPECT_FALSE(s.background.has_value());
  EXPECT_EQ(s.background_from, "none");
  EXPECT_EQ(backgroundWarning(s), "");
}

// Many tools write opaque images as RGBA: an alpha channel that is 255 everywhere is no
// alpha, and the data keeps no background (as 3DGS trains such data, on black).
TEST(Background, OpaqueRgbaImagesHaveNone) {
  TempDir d;
  writeNerfstudio(d, 255, false);
  EXPECT_TRUE(imageHasAlpha(d.file("images/f0.png")));
  EXPECT_FALSE(imageHasTransparency(d.file("images/f0.png")));
  const Scene s = loadDataset(d.str());
  EXPECT_FALSE(s.background.has_value());
  EXPECT_EQ(backgroundWarning(s), "");
}

// A manifest that says the data has no background wins; any alpha a file still has is
// composited on black, the colour the renders are against.
TEST(Background, WithNoneAnyAlphaIsCompositedOnBlack) {
  TempDir d;
  writeNerfstudio(d, 128, false);
  Scene s = loadDataset(d.str());
  BackgroundRule rule;
  rule.data_said = true;
  rule.data_from = "manifest";
  settleBackground(s, rule);
  s.resetImageCache();
  EXPECT_FALSE(s.background.has_value());
  EXPECT_EQ(s.background_from, "manifest: none");
  EXPECT_EQ(s.image(0).at(0, 0, 0), 100);  // 200 x 128/255 over black
  EXPECT_EQ(s.image(0).at(0, 0, 2), 0);
}
