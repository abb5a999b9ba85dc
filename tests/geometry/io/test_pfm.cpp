#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <limits>
#include <random>

#include "geometry/error.h"
#include "geometry/io/pfm.h"
#include "common/test_support.h"

using namespace saresgs;
using saresgs::test::readBytes;
using saresgs::test::TempDir;
using saresgs::test::throwsInputError;
using saresgs::test::writeBytes;

namespace {

ImageF randomPfmImage(int w, int h, int c, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(-1000, 1000);
  ImageF img(w, h, c);
  for (float& v : img.data) v = u(rng);
  // Values whose bits are easy to get wrong.
  img.data[0] = -0.0f;
  img.data[1] = std::numeric_limits<float>::denorm_min();
  img.data[2] = std::numeric_limits<float>::max();
  img.data[3] = std::numeric_limits<float>::infinity();
  return img;
}

std::vector<std::uint32_t> pfmBits(const std::vector<float>& v) {
  std::vector<std::uint32_t> out;
  for (float f : v) out.push_back(std::bit_cast<std::uint32_t>(f));
  return out;
}

std::string bigEndian(float f) {
  const auto u = std::bit_cast<std::uint32_t>(f);
  return {static_cast<char>(u >> 24), static_cast<char>(u >> 16), static_cast<char>(u >> 8), static_cast<char>(u)};
}

std::string littleEndian(float f) {
  const auto u = std::bit_cast<std::uint32_t>(f);
  return {static_cast<char>(u), static_cast<char>(u >> 8), static_cast<char>(u >> 16), static_cast<char>(u >> 24)};
}

void expectSameImage(const ImageF& a, const ImageF& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.channels, b.channels);
  EXPECT_EQ(pfmBits(a.data), pfmBits(b.data));
}

}  // namespace

TEST(Pfm, RoundTripOneChannelIsExact) {
  TempDir dir;
  const ImageF img = randomPfmImage(7, 5, 1, 1);
  writePfm(dir.file("depth/d.pfm"), img);  // creates the directory
  expectSameImage(img, readPfm(dir.file("depth/d.pfm")));
}

TEST(Pfm, RoundTripThreeChannelsIsExact) {
  TempDir dir;
  const ImageF img = randomPfmImage(4, 9, 3, 2);
  writePfm(dir.file("c.pfm"), img);
  expectSameImage(img, readPfm(dir.file("c.pfm")));
}

TEST(Pfm, WritesLittleEndianBottomRowFirst) {
  TempDir dir;
  ImageF img(3, 2, 1);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) img.at(x, y) = static_cast<float>(10 * y + x);
  writePfm(dir.file("a.pfm"), img);
  std::string expected = "Pf\n3 2\n-1.0\n";
  for (float v : {10.f, 11.f, 12.f, 0.f, 1.f, 2.f}) expected += littleEndian(v);
  EXPECT_EQ(readBytes(dir.file("a.pfm")), expected);
}

TEST(Pfm, ReadsHandWrittenBigEndian) {
  TempDir dir;
  // 2x2, one channel, positive scale: big-endian; the first stored row is the bottom one.
  std::string bytes = "Pf\n2 2\n1.0\n";
  for (float v : {1.5f, -2.0f, 0.25f, 1e-3f}) bytes += bigEndian(v);
  writeBytes(dir.file("be.pfm"), bytes);
  const ImageF img = readPfm(dir.file("be.pfm"));
  ASSERT_EQ(img.width, 2);
  ASSERT_EQ(img.height, 2);
  ASSERT_EQ(img.channels, 1);
  EXPECT_EQ(img.at(0, 1), 1.5f);
  EXPECT_EQ(img.at(1, 1), -2.0f);
  EXPECT_EQ(img.at(0, 0), 0.25f);
  EXPECT_EQ(img.at(1, 0), 1e-3f);
}

TEST(Pfm, ReadsThreeChannelsWithSpacesInHeader) {
  TempDir dir;
  std::string bytes = "PF 1 2 -4.5 ";
  for (float v : {1.f, 2.f, 3.f, 4.f, 5.f, 6.f}) bytes += littleEndian(v);
  writeBytes(dir.file("le.pfm"), bytes);
  const ImageF img = readPfm(dir.file("le.pfm"));
  ASSERT_EQ(img.channels, 3);
  EXPECT_EQ(img.data, (std::vector<float>{4, 5, 6, 1, 2, 3}));
}

TEST(Pfm, MalformedHeader) {
  TempDir dir;
  const std::string path = dir.file("bad.pfm");
  const std::string data = littleEndian(1.0f);
  const auto check = [&](const std::string& bytes, const std::string& field) {
    writeBytes(path, bytes);
    return throwsInputError([&] { readPfm(path); }, path, field);
  };
  EXPECT_TRUE(check("P6\n1 1\n-1\n" + data, "header: magic"));
  EXPECT_TRUE(check("pf\n1 1\n-1\n" + data, "header: magic"));
  EXPECT_TRUE(check("Pf1 1\n-1\n" + data, "header: width"));
  EXPECT_TRUE(check("Pf\n0 1\n-1\n" + data, "header: width"));
  EXPECT_TRUE(check("Pf\nx 1\n-1\n" + data, "header: width"));
  EXPECT_TRUE(check("Pf\n1 -1\n-1\n" + data, "header: height"));
  EXPECT_TRUE(check("Pf\n1 99999999999\n-1\n" + data, "header: height"));
  EXPECT_TRUE(check("Pf\n1 1\n0\n" + data, "header: scale"));
  EXPECT_TRUE(check("Pf\n1 1\nnan\n" + data, "header: scale"));
  EXPECT_TRUE(check("Pf\n1 1\nabc\n" + data, "header: scale"));
  EXPECT_TRUE(check("Pf\n1 1\n-1", "header: scale"));
  // A size that would need gigabytes must be refused before anything is allocated.
  EXPECT_TRUE(check("PF\n2000000000 2000000000\n-1\n" + data, "data"));
  EXPECT_TRUE(check("Pf\n1 1\n-1\n" + data + data, "data"));
  EXPECT_TRUE(throwsInputError([&] { readPfm(dir.file("missing.pfm")); }, "missing.pfm", "file"));
}

TEST(Pfm, TruncatedAtEveryOffset) {
  TempDir dir;
  writePfm(dir.file("good.pfm"), randomPfmImage(3, 2, 3, 3));
  const std::string full = readBytes(dir.file("good.pfm"));
  const std::string path = dir.file("bad.pfm");
  for (size_t len = 0; len < full.size(); ++len) {
    SCOPED_TRACE("truncated to " + std::to_string(len) + " bytes");
    writeBytes(path, full.substr(0, len));
    try {
      readPfm(path);
      ADD_FAILURE() << "read a truncated file";
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), path);
      EXPECT_FALSE(e.field().empty());
    }
  }
}

TEST(Pfm, WriteRefusesUnsupportedImages) {
  TempDir dir;
  EXPECT_TRUE(throwsInputError([&] { writePfm(dir.file("a.pfm"), ImageF(2, 2, 2)); }, "a.pfm", "channels"));
  EXPECT_TRUE(throwsInputError([&] { writePfm(dir.file("a.pfm"), ImageF()); }, "a.pfm", "channels"));
  ImageF broken(2, 2, 1);
  broken.data.pop_back();
  EXPECT_TRUE(throwsInputError([&] { writePfm(dir.file("a.pfm"), broken); }, "a.pfm", "image"));
}
