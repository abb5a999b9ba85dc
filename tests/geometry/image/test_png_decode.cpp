// The plain-PNG fast path (geometry/image/png_decode.h) against libpng, through OpenCV:
// files written here with every row filter, and files written by OpenCV, decode to the
// same bytes; everything the fast path must leave to OpenCV is declined.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "common/test_support.h"
#include "geometry/image/image.h"
#include "geometry/image/png_decode.h"

using namespace saresgs;

namespace {

using Bytes = std::vector<std::uint8_t>;

std::uint32_t crc32(const std::uint8_t* p, std::size_t n) {
  std::uint32_t c = 0xffffffffu;
  for (std::size_t i = 0; i < n; ++i) {
    c ^= p[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}

void put32(Bytes& out, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<std::uint8_t>(v >> s));
}

void chunk(Bytes& out, const char* type, const Bytes& data) {
  put32(out, static_cast<std::uint32_t>(data.size()));
  const std::size_t at = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data.begin(), data.end());
  put32(out, crc32(&out[at], data.size() + 4));
}

// A zlib stream of stored (uncompressed) deflate blocks.
Bytes zlibStored(const Bytes& raw) {
  Bytes z = {0x78, 0x01};
  std::size_t p = 0;
  do {
    const std::size_t n = std::min<std::size_t>(65535, raw.size() - p);
    z.push_back(p + n == raw.size() ? 1 : 0);
    z.push_back(static_cast<std::uint8_t>(n));
    z.push_back(static_cast<std::uint8_t>(n >> 8));
    z.push_back(static_cast<std::uint8_t>(~n));
    z.push_back(static_cast<std::uint8_t>(~n >> 8));
    z.insert(z.end(), raw.begin() + static_cast<long>(p), raw.begin() + static_cast<long>(p + n));
    p += n;
  } while (p < raw.size());
  std::uint32_t a = 1, b = 0;
  for (std::uint8_t v : raw) {
    a = (a + v) % 65521;
    b = (b + a) % 65521;
  }
  put32(z, (b << 16) | a);
  return z;
}

int predict(int type, int a, int b, int c) {
  switch (type) {
    case 1:
      return a;
    case 2:
      return b;
    case 3:
      return (a + b) / 2;
    case 4: {
      const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
      return pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
    }
    default:
      return 0;
  }
}

struct PngSpec {
  int colour = 2;  // 2 RGB, 6 RGBA, anything else written as given
  int depth = 8;
  int interlace = 0;
  bool trns = false;    // a tRNS chunk before the data
  bool text = true;     // an ancillary tEXt chunk (skipped) between IHDR and IDAT
  int idat_chunks = 1;  // the zlib stream split over this many IDATs
  int filter = -1;      // every row's filter; -1: row y uses y % 5
};

// Writes img (RGB or RGBA bytes) as a PNG with the spec's chunks and row filters.
Bytes encodePng(const Image8& img, const PngSpec& s) {
  const int bpp = img.channels;
  const std::size_t row_bytes = static_cast<std::size_t>(img.width) * bpp;
  Bytes raw;
  for (int y = 0; y < img.height; ++y) {
    const int type = s.filter >= 0 ? s.filter : y % 5;
    raw.push_back(static_cast<std::uint8_t>(type));
    const std::uint8_t* row = &img.data[static_cast<std::size_t>(y) * row_bytes];
    const std::uint8_t* up = y ? row - row_bytes : nullptr;
    for (std::size_t i = 0; i < row_bytes; ++i) {
      const int a = i >= static_cast<std::size_t>(bpp) ? row[i - bpp] : 0, b = up ? up[i] : 0;
      const int c = up && i >= static_cast<std::size_t>(bpp) ? up[i - bpp] : 0;
      raw.push_back(static_cast<std::uint8_t>(row[i] - predict(type, a, b, c)));
    }
  }
  Bytes out = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  Bytes ihdr;
  put32(ihdr, static_cast<std::uint32_t>(img.width));
  put32(ihdr, static_cast<std::uint32_t>(img.height));
  ihdr.insert(ihdr.end(), {static_cast<std::uint8_t>(s.depth), static_cast<std::uint8_t>(s.colour), 0, 0,
                           static_cast<std::uint8_t>(s.interlace)});
  chunk(out, "IHDR", ihdr);
  if (s.text) chunk(out, "tEXt", Bytes{'k', 0, 'v'});
  if (s.trns) chunk(out, "tRNS", Bytes{0, 1, 0, 2, 0, 3});
  const Bytes z = zlibStored(raw);
  const std::size_t part = (z.size() + s.idat_chunks - 1) / s.idat_chunks;
  for (std::size_t p = 0; p < z.size(); p += part)
    chunk(out, "IDAT",
          Bytes(z.begin() + static_cast<long>(p), z.begin() + static_cast<long>(std::min(z.size(), p + part))));
  chunk(out, "IEND", {});
  return out;
}

// The file with IHDR's width and height replaced (and its CRC made right again).
Bytes withSize(Bytes b, std::uint32_t w, std::uint32_t h) {
  for (int k = 0; k < 4; ++k) {
    b[16 + k] = static_cast<std::uint8_t>(w >> (24 - 8 * k));
    b[20 + k] = static_cast<std::uint8_t>(h >> (24 - 8 * k));
  }
  const std::uint32_t crc = crc32(&b[12], 17);  // IHDR's type and 13 data bytes
  for (int k = 0; k < 4; ++k) b[29 + k] = static_cast<std::uint8_t>(crc >> (24 - 8 * k));
  return b;
}

Image8 randomPngImage(int w, int h, int c, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Image8 img(w, h, c);
  for (auto& v : img.data) v = static_cast<std::uint8_t>(rng() & 0xff);
  return img;
}

void writePngBytes(const std::string& path, const Bytes& b) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), static_cast<long>(b.size()));
}

Bytes pngFileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), {});
}

// libpng's reading of the file, through OpenCV, in RGB(A) order: what readImage gave
// before the fast path.
Image8 openCvRead(const std::string& path, bool keep_alpha) {
  const cv::Mat m = cv::imread(path, keep_alpha ? cv::IMREAD_UNCHANGED : cv::IMREAD_COLOR);
  if (m.empty()) return {};
  Image8 out(m.cols, m.rows, m.channels());
  cv::Mat dst(out.height, out.width, CV_8UC(out.channels), out.data.data());
  cv::cvtColor(m, dst, m.channels() == 4 ? cv::COLOR_BGRA2RGBA : cv::COLOR_BGR2RGB);
  return out;
}

}  // namespace

TEST(PlainPng, EveryRowFilterDecodesAsLibpngDoes) {
  test::TempDir d;
  int checked = 0;
  for (int c : {3, 4})
    for (auto [w, h] : {std::pair{1, 1}, {2, 7}, {37, 23}, {64, 17}})
      for (int filter : {-1, 0, 1, 2, 3, 4}) {
        // Noise reaches every wrap-around of the byte sums; a ramp makes Paeth's three
        // choices and the Average's rounding matter.
        Image8 img = randomPngImage(w, h, c, static_cast<std::uint64_t>(w * 131 + h * 7 + c + filter * 1000 + 5000));
        if (filter == 4)
          for (std::size_t i = 0; i < img.data.size(); i += 2) img.data[i] = static_cast<std::uint8_t>(i * 3);
        PngSpec s;
        s.colour = c == 4 ? 6 : 2;
        s.filter = filter;
        s.idat_chunks = (w * h) % 3 + 1;
        const Bytes file = encodePng(img, s);
        writePngBytes(d.file("f.png"), file);
        for (bool keep_alpha : {true, false}) {
          SCOPED_TRACE(testing::Message() << "channels " << c << ", " << w << "x" << h << ", filter " << filter
                                          << ", keep_alpha " << keep_alpha);
          const Image8 want = openCvRead(d.file("f.png"), keep_alpha);
          ASSERT_FALSE(want.empty());
          const auto got = decodePlainPng(file, keep_alpha);
          ASSERT_TRUE(got.has_value());
          EXPECT_EQ(got->width, w);
          EXPECT_EQ(got->height, h);
          EXPECT_EQ(got->channels, want.channels);
          EXPECT_EQ(got->data, want.data);
          // readImage takes the fast path and gives the same.
          EXPECT_EQ(readImage(d.file("f.png"), keep_alpha).data, want.data);
          ++checked;
        }
      }
  EXPECT_EQ(checked, 2 * 4 * 6 * 2);
}

TEST(PlainPng, FilesOpenCvWritesTakeTheFastPath) {
  // The datasets' own images: compressed by zlib (not stored), the filters OpenCV picks.
  test::TempDir d;
  for (int c : {3, 4}) {
    Image8 img = randomPngImage(96, 40, c, 77 + c);
    for (int y = 20; y < 40; ++y)  // a smooth half, so that the stream has real matches
      for (int x = 0; x < 96; ++x)
        for (int k = 0; k < c; ++k) img.at(x, y, k) = static_cast<std::uint8_t>(x + 2 * y + 40 * k);
    writeImage(d.file("cv.png"), img);
    const Bytes file = pngFileBytes(d.file("cv.png"));
    const auto got = decodePlainPng(file, true);
    ASSERT_TRUE(got.has_value()) << c;
    EXPECT_EQ(got->data, img.data);
    EXPECT_EQ(got->data, openCvRead(d.file("cv.png"), true).data);
  }
}

TEST(PlainPng, DeclinesWhatOpenCvMustInterpret) {
  const Image8 rgb = randomPngImage(9, 6, 3, 1);
  const Bytes good = encodePng(rgb, {});
  ASSERT_TRUE(decodePlainPng(good, true).has_value());
  auto declined = [](const Bytes& b) { return !decodePlainPng(b, true).has_value(); };
  PngSpec s;
  s.trns = true;
  EXPECT_TRUE(declined(encodePng(rgb, s)));  // transparency: alpha OpenCV may add
  s = {};
  s.interlace = 1;
  EXPECT_TRUE(declined(encodePng(rgb, s)));
  s = {};
  s.colour = 0;  // grey, read as if RGB bytes: the header alone must decline it
  EXPECT_TRUE(declined(encodePng(rgb, s)));
  s = {};
  s.depth = 16;
  EXPECT_TRUE(declined(encodePng(rgb, s)));
  // 16-bit and grey files written by OpenCV: declined, and readImage still converts them.
  test::TempDir d;
  cv::Mat g16(5, 6, CV_16UC1, cv::Scalar(65535));
  cv::imwrite(d.file("g16.png"), g16);
  EXPECT_TRUE(declined(pngFileBytes(d.file("g16.png"))));
  EXPECT_EQ(readImage(d.file("g16.png")).at(2, 2, 1), 255);
  cv::Mat g8(5, 6, CV_8UC1, cv::Scalar(9));
  cv::imwrite(d.file("g8.png"), g8);
  EXPECT_TRUE(declined(pngFileBytes(d.file("g8.png"))));
}

TEST(PlainPng, DeclinesEveryDamageAndOpenCvJudgesIt) {
  const Image8 rgb = randomPngImage(11, 8, 3, 2);
  const Bytes good = encodePng(rgb, {});
  test::TempDir d;
  std::vector<std::pair<std::string, Bytes>> bad;
  for (std::size_t at : {std::size_t{20}, std::size_t{40}, good.size() - 20, good.size() - 2}) {
    Bytes b = good;
    b[at] ^= 0x10;  // a chunk's data or CRC: the CRC no longer matches
    bad.emplace_back("flipped byte " + std::to_string(at), b);
  }
  for (std::size_t keep : {std::size_t{8}, std::size_t{33}, good.size() / 2, good.size() - 12, good.size() - 1})
    bad.emplace_back("cut to " + std::to_string(keep), Bytes(good.begin(), good.begin() + static_cast<long>(keep)));
  {
    // A filter type PNG does not define: the encoder writes it with no prediction, so the
    // stream and every CRC are right and only the filter is wrong.
    PngSpec s;
    s.filter = 5;
    bad.emplace_back("filter type 5", encodePng(rgb, s));
  }
  // A header that claims far more pixels than the data holds: declined before any
  // allocation of that size.
  bad.emplace_back("4194304 x 4194304", withSize(good, 4194304, 4194304));
  // Under the pixel cap but past what its 300-byte stream could inflate to.
  bad.emplace_back("11 x 600000", withSize(good, 11, 600000));
  for (const auto& [what, b] : bad) {
    SCOPED_TRACE(what);
    EXPECT_FALSE(decodePlainPng(b, true).has_value());
    // readImage gives OpenCV's verdict: its image, or InputError naming the file.
    writePngBytes(d.file("bad.png"), b);
    const Image8 want = openCvRead(d.file("bad.png"), true);
    if (want.empty()) {
      EXPECT_TRUE(test::throwsInputError([&] { readImage(d.file("bad.png"), true); }, "bad.png", "file"));
    } else {
      EXPECT_EQ(readImage(d.file("bad.png"), true).data, want.data);
    }
  }
}
