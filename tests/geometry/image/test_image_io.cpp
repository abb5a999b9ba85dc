#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <random>
#include <tuple>

#include "common/test_support.h"
#include "geometry/image/image.h"

using namespace saresgs;

namespace {
Image8 randomImage8(int w, int h, int c, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Image8 img(w, h, c);
  for (auto& v : img.data) v = static_cast<std::uint8_t>(rng() & 0xff);
  return img;
}
}  // namespace

TEST(ImageIO, PngRoundTripIsExactForRgbAndRgba) {
  test::TempDir d;
  for (int c : {3, 4}) {
    const Image8 img = randomImage8(37, 23, c, c);
    writeImage(d.file("x.png"), img);
    const Image8 back = readImage(d.file("x.png"), /*keep_alpha=*/true);
    EXPECT_EQ(back.channels, c);
    EXPECT_EQ(back.data, img.data);
  }
  // Without keep_alpha an RGBA file comes back as RGB.
  EXPECT_EQ(readImage(d.file("x.png")).channels, 3);
}

TEST(ImageIO, ChannelOrderIsRgbOnDisk) {
  test::TempDir d;
  Image8 red(4, 4, 3, 0);
  for (int i = 0; i < 16; ++i) red.data[i * 3] = 255;
  writeImage(d.file("red.png"), red);
  // OpenCV reads BGR: a red pixel is (0, 0, 255) there.
  const cv::Mat m = cv::imread(d.file("red.png"));
  EXPECT_EQ(m.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 255));
}

TEST(ImageIO, SixteenBitAndGreyAreConverted) {
  test::TempDir d;
  cv::Mat g16(5, 6, CV_16UC1, cv::Scalar(65535));
  cv::imwrite(d.file("g16.png"), g16);
  const Image8 img = readImage(d.file("g16.png"));
  EXPECT_EQ(img.channels, 3);
  EXPECT_EQ(img.at(2, 2, 1), 255);
}

TEST(ImageIO, FloatConversionClampsAndRounds) {
  ImageF f(2, 1, 3);
  f.data = {-0.5f, 0.5f, 1.5f, std::nanf(""), 1.0f / 255.0f, 0.9999f};
  const Image8 b = toByte(f);
  EXPECT_EQ(b.data, (std::vector<std::uint8_t>{0, 128, 255, 0, 1, 255}));
  EXPECT_FLOAT_EQ(toFloat(b).data[2], 1.0f);
}

// Converting into a reused image gives what a fresh conversion gives, whatever the
// image held before (larger, smaller, another channel count).
TEST(ImageIO, FloatConversionIntoAReusedImageEqualsAFreshOne) {
  ImageF out;
  for (const auto& [w, h, c] :
       {std::tuple{31, 17, 3}, std::tuple{5, 4, 3}, std::tuple{40, 20, 4}, std::tuple{3, 2, 1}}) {
    const Image8 img = randomImage8(w, h, c, static_cast<std::uint64_t>(w * 100 + c));
    toFloatInto(img, out);
    const ImageF fresh = toFloat(img);
    EXPECT_EQ(out.width, w);
    EXPECT_EQ(out.height, h);
    EXPECT_EQ(out.channels, c);
    EXPECT_EQ(out.data, fresh.data);
    for (std::size_t i = 0; i < img.data.size(); ++i)
      ASSERT_NEAR(out.data[i], img.data[i] / 255.0, 1.2e-7);  // within two ulps
  }
}

// An 8-bit grey file comes back as RGB with each channel the grey value.
TEST(ImageIO, GreyIsReplicatedIntoRgb) {
  test::TempDir d;
  const Image8 grey = randomImage8(13, 9, 1, 5);
  cv::Mat m(9, 13, CV_8UC1, const_cast<std::uint8_t*>(grey.data.data()));
  cv::imwrite(d.file("grey.png"), m);
  const Image8 img = readImage(d.file("grey.png"), /*keep_alpha=*/true);
  ASSERT_EQ(img.channels, 3);
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 13; ++x)
      for (int ch = 0; ch < 3; ++ch) ASSERT_EQ(img.at(x, y, ch), grey.at(x, y, 0));
}

TEST(ImageIO, UnreadableFilesNameTheFile) {
  test::TempDir d;
  EXPECT_TRUE(test::throwsInputError([&] { readImage(d.file("none.png")); }, "none.png", "file"));
  test::writeBytes(d.file("bad.png"), "not a png");
  EXPECT_TRUE(test::throwsInputError([&] { readImage(d.file("bad.png")); }, "bad.png", "file"));
  EXPECT_TRUE(test::throwsInputError([&] { writeImage(d.file("x.tga0"), Image8(2, 2, 3)); }, "x.tga0", "extension"));
}
