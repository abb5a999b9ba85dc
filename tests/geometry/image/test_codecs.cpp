// Our PNG and JPEG codecs (geometry/image/codecs.h, libpng and libjpeg-turbo directly)
// against OpenCV's imgcodecs, which readImage used before: the same pixels for every kind
// of PNG OpenCV writes or libpng reads, for JPEGs with each EXIF orientation, and for what
// we write read back by OpenCV.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "common/test_support.h"
#include "geometry/error.h"
#include "geometry/image/codecs.h"
#include "geometry/image/image.h"

namespace saresgs {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes codecFileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), {});
}

// OpenCV's reading, in RGB(A) order, 16-bit samples rounded to 8 as readImage did.
Image8 openCv(const std::string& path, int flags) {
  cv::Mat m = cv::imread(path, flags);
  if (m.empty()) return {};
  if (m.depth() == CV_16U) m.convertTo(m, CV_8U, 1.0 / 257.0);
  Image8 out(m.cols, m.rows, m.channels() == 4 ? 4 : 3);
  cv::Mat dst(out.height, out.width, CV_8UC(out.channels), out.data.data());
  cv::cvtColor(m, dst,
               m.channels() == 1   ? cv::COLOR_GRAY2RGB
               : m.channels() == 4 ? cv::COLOR_BGRA2RGBA
                                   : cv::COLOR_BGR2RGB);
  return out;
}

cv::Mat noise(int rows, int cols, int type, std::uint64_t seed) {
  cv::Mat m(rows, cols, type);
  cv::RNG rng(seed);
  rng.fill(m, cv::RNG::UNIFORM, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
  return m;
}

TEST(Codecs, EveryKindOfPngDecodesAsOpenCvReadsIt) {
  test::TempDir d;
  struct Case {
    const char* what;
    cv::Mat m;
    std::vector<int> params;
  };
  std::vector<Case> cases = {
      {"grey 8", noise(13, 17, CV_8UC1, 1), {}},
      {"grey 16", noise(13, 17, CV_16UC1, 2), {}},
      {"rgb 8", noise(9, 31, CV_8UC3, 3), {}},
      {"rgb 16", noise(9, 31, CV_16UC3, 4), {}},
      {"rgba 8", noise(21, 5, CV_8UC4, 5), {}},
      {"rgba 16", noise(21, 5, CV_16UC4, 6), {}},
      {"grey 1 bit", noise(16, 24, CV_8UC1, 7) > 128, {cv::IMWRITE_PNG_BILEVEL, 1}},
  };
  int checked = 0;
  for (const Case& c : cases)
    for (bool keep_alpha : {true, false}) {
      SCOPED_TRACE(std::string(c.what) + (keep_alpha ? ", with alpha" : ", without"));
      const std::string path = d.file("c.png");
      ASSERT_TRUE(cv::imwrite(path, c.m, c.params));
      const Image8 want = openCv(path, keep_alpha ? cv::IMREAD_UNCHANGED : cv::IMREAD_COLOR);
      ASSERT_FALSE(want.empty());
      const auto got = decodePng(codecFileBytes(path), keep_alpha);
      ASSERT_TRUE(got.has_value());
      EXPECT_EQ(got->channels, want.channels);
      EXPECT_EQ(got->data, want.data);
      EXPECT_EQ(readImage(path, keep_alpha).data, want.data);
      ++checked;
    }
  EXPECT_EQ(checked, 14);
}

// A JPEG with an APP1 Exif block whose only entry is the Orientation tag.
Bytes withOrientation(const Bytes& jpeg, int orientation) {
  const Bytes exif = {'E',  'x',  'i', 'f', 0, 0, 'M', 'M', 0, 42,
                      0,    0,    0,   8,  // TIFF header, IFD at 8
                      0,    1,             // one entry
                      0x01, 0x12, 0,   3,   0, 0, 0,   1,   0, static_cast<std::uint8_t>(orientation),
                      0,    0,    0,   0,   0, 0};  // no next IFD
  const std::size_t len = exif.size() + 2;
  Bytes out(jpeg.begin(), jpeg.begin() + 2);  // SOI
  out.insert(out.end(), {0xff, 0xe1, static_cast<std::uint8_t>(len >> 8), static_cast<std::uint8_t>(len & 0xff)});
  out.insert(out.end(), exif.begin(), exif.end());
  out.insert(out.end(), jpeg.begin() + 2, jpeg.end());
  return out;
}

TEST(Codecs, JpegsDecodeAsOpenCvWithEachExifOrientationOrAsStored) {
  test::TempDir d;
  cv::Mat m(24, 40, CV_8UC3);
  for (int y = 0; y < m.rows; ++y)
    for (int x = 0; x < m.cols; ++x) m.at<cv::Vec3b>(y, x) = cv::Vec3b(x * 6, y * 10, (x * y) % 256);
  std::vector<std::uint8_t> plain;
  ASSERT_TRUE(cv::imencode(".jpg", m, plain, {cv::IMWRITE_JPEG_QUALITY, 90}));
  for (int o = 1; o <= 8; ++o) {
    SCOPED_TRACE("orientation " + std::to_string(o));
    const Bytes file = withOrientation(plain, o);
    std::ofstream(d.file("o.jpg"), std::ios::binary)
        .write(reinterpret_cast<const char*>(file.data()), static_cast<long>(file.size()));
    EXPECT_EQ(jpegExifOrientation(file), o);
    const Image8 turned = openCv(d.file("o.jpg"), cv::IMREAD_COLOR);
    const Image8 stored = openCv(d.file("o.jpg"), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(turned.empty());
    EXPECT_EQ(turned.width, o >= 5 ? 24 : 40);
    const auto got = decodeJpeg(file, true);
    ASSERT_TRUE(got.has_value());
    EXPECT_EQ(got->width, turned.width);
    EXPECT_EQ(got->data, turned.data);
    EXPECT_EQ(readImage(d.file("o.jpg")).data, turned.data);
    EXPECT_EQ(readImage(d.file("o.jpg"), /*keep_alpha=*/true).data, stored.data);
  }
  // A grey JPEG is replicated into RGB as OpenCV does.
  cv::Mat grey = noise(10, 12, CV_8UC1, 9);
  ASSERT_TRUE(cv::imwrite(d.file("g.jpg"), grey));
  EXPECT_EQ(readImage(d.file("g.jpg")).data, openCv(d.file("g.jpg"), cv::IMREAD_COLOR).data);
}

TEST(Codecs, WhatWeWriteOpenCvReadsBack) {
  test::TempDir d;
  for (int c : {1, 3, 4}) {
    Image8 img(33, 19, c);
    std::mt19937 rng(static_cast<unsigned>(c));
    for (auto& v : img.data) v = static_cast<std::uint8_t>(rng());
    const Bytes png = encodePng(img);
    const cv::Mat back = cv::imdecode(png, cv::IMREAD_UNCHANGED);
    ASSERT_EQ(back.channels(), c);
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x)
        for (int k = 0; k < c; ++k) {
          const int cv_k = c >= 3 && k < 3 ? 2 - k : k;  // OpenCV's BGR(A)
          ASSERT_EQ(back.ptr<std::uint8_t>(y)[x * c + cv_k], img.at(x, y, k)) << c << " " << x << "," << y;
        }
    // A JPEG: lossy, so close on a smooth image, and the same size.
    Image8 smooth(48, 32, c);
    for (int y = 0; y < smooth.height; ++y)
      for (int x = 0; x < smooth.width; ++x)
        for (int k = 0; k < c; ++k) smooth.at(x, y, k) = static_cast<std::uint8_t>(3 * x + 2 * y + 20 * k);
    const cv::Mat j = cv::imdecode(encodeJpeg(smooth, 95), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(j.cols, 48);
    ASSERT_EQ(j.rows, 32);
    ASSERT_EQ(j.channels(), c == 1 ? 1 : 3);
    const int cv_k = c == 1 ? 0 : 2;  // red, the first channel, is OpenCV's last
    EXPECT_NEAR(j.ptr<std::uint8_t>(16)[20 * j.channels() + cv_k], smooth.at(20, 16, 0), 4);
  }
  EXPECT_THROW(encodeImage(Image8(2, 2, 3), ".bmp"), InputError);
  EXPECT_EQ(encodeImage(Image8(2, 2, 3), ".PNG"), encodePng(Image8(2, 2, 3)));
}

TEST(Codecs, DamagedAndForeignFilesAreRefusedWithTheReason) {
  test::TempDir d;
  std::string why;
  EXPECT_FALSE(decodePng(Bytes{0x89, 'P', 'N', 'G'}, true, &why).has_value());
  EXPECT_FALSE(why.empty());
  why.clear();
  EXPECT_FALSE(decodeJpeg(Bytes{0xff, 0xd8, 0xff, 0xe0, 0, 4}, false, &why).has_value());
  EXPECT_FALSE(why.empty());
  std::ofstream(d.file("x.bmp"), std::ios::binary) << "BM not really a bitmap";
  try {
    (void)readImage(d.file("x.bmp"));
    ADD_FAILURE() << "read a BMP";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("neither PNG nor JPEG"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace saresgs
