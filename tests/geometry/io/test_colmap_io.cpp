#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>

#include "geometry/error.h"
#include "geometry/io/colmap.h"
#include "common/test_support.h"

using namespace saresgs;
using saresgs::test::readBytes;
using saresgs::test::TempDir;
using saresgs::test::throwsInputError;
using saresgs::test::writeBytes;

namespace {

namespace fs = std::filesystem;

void addCamera(ColmapModel& m, std::uint32_t id, const std::string& model, std::uint64_t w, std::uint64_t h,
               std::vector<double> params) {
  ColmapCamera c;
  c.id = id;
  c.model = model;
  c.width = w;
  c.height = h;
  c.params = std::move(params);
  m.cameras[id] = c;
}

// Random cameras of both pinhole models and one OPENCV, images with random unit
// quaternions and 2D points, and points whose tracks match the images' point ids.
ColmapModel randomColmapModel(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> n(0, 1);
  ColmapModel m;
  addCamera(m, 1, "SIMPLE_PINHOLE", 640, 480, {500 + 50 * u(rng), 320 + u(rng), 240 + u(rng)});
  addCamera(m, 2, "PINHOLE", 1920, 1080, {1400 * u(rng) + 1, 1400 * u(rng) + 1, 960 * u(rng), 540 * u(rng)});
  addCamera(m, 7, "PINHOLE", 800, 600, {600 + u(rng), 601 + u(rng), 400.5, 300.25});
  addCamera(m, 4000000000u, "SIMPLE_PINHOLE", 3, 5, {1e-3 * u(rng), -1e10 * u(rng), 1e-300});
  addCamera(m, 9, "OPENCV", 1280, 720,
            {900 + u(rng), 905 + u(rng), 640 + u(rng), 360 + u(rng), -0.1 * u(rng), 0.01 * u(rng), 1e-4 * n(rng),
             -1e-4 * n(rng)});
  std::vector<std::uint32_t> camera_ids;
  for (const auto& [id, c] : m.cameras) camera_ids.push_back(id);

  const std::vector<std::string> names{"a.png",          "sub/dir/b.jpg", "frame 0007.png", "d.JPG",
                                       "e_\xC3\xA9.png", "f.png",         "g.png"};
  for (size_t k = 0; k < names.size(); ++k) {
    ColmapImage img;
    img.id = static_cast<std::uint32_t>(3 * k + 1);
    img.q = Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized();
    img.t = Eigen::Vector3d(n(rng), n(rng), n(rng)) * 10;
    img.camera_id = camera_ids[rng() % camera_ids.size()];
    img.name = names[k];
    const size_t count = k == 2 ? 0 : 1 + rng() % 12;  // image 7 has no 2D points
    for (size_t i = 0; i < count; ++i) {
      img.xys.emplace_back(2000 * u(rng) - 10, 1000 * u(rng));
      img.point3d_ids.push_back(kInvalidPoint3DId);
    }
    m.images[img.id] = img;
  }
  // Extreme but finite values must survive too.
  m.images[1].xys[0] = {-0.0, std::numeric_limits<double>::denorm_min()};
  m.images[1].t.x() = std::numeric_limits<double>::max();

  std::vector<std::pair<std::uint32_t, std::uint32_t>> slots;
  for (const auto& [id, img] : m.images)
    for (size_t i = 0; i < img.xys.size(); ++i) slots.emplace_back(id, static_cast<std::uint32_t>(i));
  std::shuffle(slots.begin(), slots.end(), rng);
  std::uint64_t pid = 5;
  while (slots.size() > 6) {  // leave a few 2D points without a 3D point
    ColmapPoint3D p;
    p.id = pid;
    pid = pid == 5 ? 5000000000ull : pid + 1 + rng() % 5;  // one id above 2^32
    p.xyz = Eigen::Vector3d(n(rng), n(rng), n(rng)) * 3;
    p.rgb = {static_cast<std::uint8_t>(rng()), static_cast<std::uint8_t>(rng()), 255};
    p.error = u(rng);
    const size_t length = 1 + rng() % 3;
    for (size_t k = 0; k < length && !slots.empty(); ++k) {
      const auto [image_id, idx] = slots.back();
      slots.pop_back();
      p.track.push_back({image_id, idx});
      m.images[image_id].point3d_ids[idx] = p.id;
    }
    m.points[p.id] = p;
  }
  return m;
}

std::vector<std::uint64_t> bits(std::initializer_list<double> values) {
  std::vector<std::uint64_t> out;
  for (double v : values) out.push_back(std::bit_cast<std::uint64_t>(v));
  return out;
}

std::vector<std::uint64_t> bits(const std::vector<double>& values) {
  std::vector<std::uint64_t> out;
  for (double v : values) out.push_back(std::bit_cast<std::uint64_t>(v));
  return out;
}

std::vector<std::uint64_t> bits(const std::vector<Eigen::Vector2d>& xys) {
  std::vector<std::uint64_t> out;
  for (const auto& p : xys) {
    out.push_back(std::bit_cast<std::uint64_t>(p.x()));
    out.push_back(std::bit_cast<std::uint64_t>(p.y()));
  }
  return out;
}

// Every field equal, doubles bit for bit.
void expectSameModel(const ColmapModel& a, const ColmapModel& b) {
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  for (auto ia = a.cameras.begin(), ib = b.cameras.begin(); ia != a.cameras.end(); ++ia, ++ib) {
    SCOPED_TRACE("camera " + std::to_string(ia->first));
    EXPECT_EQ(ia->first, ib->first);
    EXPECT_EQ(ia->second.id, ib->second.id);
    EXPECT_EQ(ia->second.model, ib->second.model);
    EXPECT_EQ(ia->second.width, ib->second.width);
    EXPECT_EQ(ia->second.height, ib->second.height);
    EXPECT_EQ(bits(ia->second.params), bits(ib->second.params));
  }
  ASSERT_EQ(a.images.size(), b.images.size());
  for (auto ia = a.images.begin(), ib = b.images.begin(); ia != a.images.end(); ++ia, ++ib) {
    SCOPED_TRACE("image " + std::to_string(ia->first));
    const ColmapImage& x = ia->second;
    const ColmapImage& y = ib->second;
    EXPECT_EQ(ia->first, ib->first);
    EXPECT_EQ(x.id, y.id);
    EXPECT_EQ(bits({x.q.w(), x.q.x(), x.q.y(), x.q.z(), x.t.x(), x.t.y(), x.t.z()}),
              bits({y.q.w(), y.q.x(), y.q.y(), y.q.z(), y.t.x(), y.t.y(), y.t.z()}));
    EXPECT_EQ(x.camera_id, y.camera_id);
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(bits(x.xys), bits(y.xys));
    EXPECT_EQ(x.point3d_ids, y.point3d_ids);
  }
  ASSERT_EQ(a.points.size(), b.points.size());
  for (auto ia = a.points.begin(), ib = b.points.begin(); ia != a.points.end(); ++ia, ++ib) {
    SCOPED_TRACE("point " + std::to_string(ia->first));
    const ColmapPoint3D& x = ia->second;
    const ColmapPoint3D& y = ib->second;
    EXPECT_EQ(ia->first, ib->first);
    EXPECT_EQ(x.id, y.id);
    EXPECT_EQ(bits({x.xyz.x(), x.xyz.y(), x.xyz.z(), x.error}), bits({y.xyz.x(), y.xyz.y(), y.xyz.z(), y.error}));
    EXPECT_EQ(x.rgb, y.rgb);
    EXPECT_EQ(x.track, y.track);
  }
}

// A small valid model: one camera, one image with two 2D points, one point.
ColmapModel tinyModel() {
  ColmapModel m;
  addCamera(m, 1, "PINHOLE", 64, 48, {50, 51, 32, 24});
  ColmapImage img;
  img.id = 1;
  img.camera_id = 1;
  img.name = "a.png";
  img.xys = {{1.5, 2.5}, {3.5, 4.5}};
  img.point3d_ids = {1, kInvalidPoint3DId};
  m.images[1] = img;
  ColmapPoint3D p;
  p.id = 1;
  p.xyz = {1, 2, 3};
  p.track = {{1, 0}};
  m.points[1] = p;
  return m;
}

void writeText(const TempDir& dir, const std::string& cameras, const std::string& images, const std::string& points) {
  writeBytes(dir.file("cameras.txt"), cameras);
  writeBytes(dir.file("images.txt"), images);
  writeBytes(dir.file("points3D.txt"), points);
}

const std::string kCameras = "1 PINHOLE 640 480 500 500 320 240\n";
const std::string kImages = "1 1 0 0 0 0 0 0 1 a.png\n10 20 -1\n";
const std::string kPoints = "";

// Overwrites bytes of a file at `offset`.
template <typename T>
void patch(const std::string& path, size_t offset, T value) {
  std::string bytes = readBytes(path);
  ASSERT_LE(offset + sizeof(T), bytes.size());
  std::memcpy(bytes.data() + offset, &value, sizeof(T));  // the test host is little-endian
  writeBytes(path, bytes);
}

}  // namespace

TEST(ColmapModels, TableMatchesColmap) {
  const std::vector<std::pair<std::string, int>> expected{{"SIMPLE_PINHOLE", 3},
                                                          {"PINHOLE", 4},
                                                          {"SIMPLE_RADIAL", 4},
                                                          {"RADIAL", 5},
                                                          {"OPENCV", 8},
                                                          {"OPENCV_FISHEYE", 8},
                                                          {"FULL_OPENCV", 12},
                                                          {"FOV", 5},
                                                          {"SIMPLE_RADIAL_FISHEYE", 4},
                                                          {"RADIAL_FISHEYE", 5},
                                                          {"THIN_PRISM_FISHEYE", 12}};
  for (int id = 0; id < static_cast<int>(expected.size()); ++id) {
    EXPECT_EQ(colmapModelName(id), expected[static_cast<size_t>(id)].first);
    EXPECT_EQ(colmapModelId(expected[static_cast<size_t>(id)].first), id);
    EXPECT_EQ(colmapModelParamCount(id), expected[static_cast<size_t>(id)].second);
  }
  EXPECT_EQ(colmapModelId("pinhole"), -1);
  EXPECT_EQ(colmapModelParamCount(11), -1);
  EXPECT_EQ(colmapModelParamCount(-1), -1);
  EXPECT_EQ(colmapModelName(11), "");
}

TEST(ColmapIo, TextRoundTripIsExact) {
  TempDir dir;
  const ColmapModel m = randomColmapModel(1);
  writeColmapText(dir.file("sparse/0"), m);  // creates the directories
  expectSameModel(m, readColmapText(dir.file("sparse/0")));
  expectSameModel(m, readColmapModel(dir.file("sparse/0")));
}

TEST(ColmapIo, BinaryRoundTripIsExact) {
  TempDir dir;
  const ColmapModel m = randomColmapModel(2);
  writeColmapBinary(dir.file("sparse/0"), m);
  expectSameModel(m, readColmapBinary(dir.file("sparse/0")));
  expectSameModel(m, readColmapModel(dir.file("sparse/0")));
}

TEST(ColmapIo, TextBinaryTextRoundTripIsExact) {
  TempDir dir;
  const ColmapModel m = randomColmapModel(3);
  writeColmapText(dir.file("text1"), m);
  writeColmapBinary(dir.file("bin"), readColmapText(dir.file("text1")));
  writeColmapText(dir.file("text2"), readColmapBinary(dir.file("bin")));
  expectSameModel(m, readColmapText(dir.file("text2")));
  for (const char* name : {"cameras.txt", "images.txt", "points3D.txt"})
    EXPECT_EQ(readBytes(dir.file(std::string("text1/") + name)), readBytes(dir.file(std::string("text2/") + name)))
        << name;
}

TEST(ColmapIo, WritersLeaveOnlyTheModelFiles) {
  TempDir dir;
  const ColmapModel m = randomColmapModel(4);
  writeColmapText(dir.str(), m);
  writeColmapBinary(dir.str(), m);
  writeColmapBinary(dir.str(), m);  // overwriting works too
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir.str())) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"cameras.bin", "cameras.txt", "images.bin", "images.txt", "points3D.bin",
                                             "points3D.txt"}));
}

TEST(ColmapIo, TextHeaderHasColmapComments) {
  TempDir dir;
  writeColmapText(dir.str(), tinyModel());
  const std::string cameras = readBytes(dir.file("cameras.txt"));
  EXPECT_EQ(cameras.rfind("# Camera list with one line of data per camera:\n", 0), 0u) << cameras;
  EXPECT_NE(cameras.find("# Number of cameras: 1\n"), std::string::npos);
  EXPECT_NE(readBytes(dir.file("images.txt")).find("# Number of images: 1,"), std::string::npos);
  EXPECT_NE(readBytes(dir.file("points3D.txt")).find("# Number of points: 1,"), std::string::npos);
}

TEST(ColmapIo, ReadModelPrefersBinary) {
  TempDir dir;
  const ColmapModel text = randomColmapModel(5);
  const ColmapModel binary = randomColmapModel(6);
  writeColmapText(dir.str(), text);
  expectSameModel(text, readColmapModel(dir.str()));
  writeColmapBinary(dir.str(), binary);
  expectSameModel(binary, readColmapModel(dir.str()));
}

TEST(ColmapIo, HandWrittenTextModel) {
  TempDir dir;
  writeText(dir,
            "# Camera list with one line of data per camera:\n"
            "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
            "# Number of cameras: 2\n"
            "1 PINHOLE 640 480 500.5 501.25 320 240.5\n"
            "\n"
            "3 SIMPLE_RADIAL 1920 1080 1400 960 540 -0.0125\n",
            "# Image list with two lines of data per image:\n"
            "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
            "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
            "# Number of images: 2, mean observations per image: 1\n"
            "1 0.5 0.5 -0.5 0.5 1.5 -2 3.25 1 left/0001.png\n"
            "10.5 20.25 7 300 400 -1 33.125 44 8\n"
            "\n"
            "2 1 0 0 0 0 0 1e-3 3 0002.png\n"
            "\n",
            "# 3D point list with one line of data per point:\n"
            "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
            "# Number of points: 2, mean track length: 1\n"
            "7 1 2 3 255 128 0 0.5 1 0\n"
            "8 -1.5 0.25 1e3 10 20 30 1.25 1 2\n");
  const ColmapModel m = readColmapModel(dir.str());

  ASSERT_EQ(m.cameras.size(), 2u);
  const ColmapCamera& c1 = m.cameras.at(1);
  EXPECT_EQ(c1.id, 1u);
  EXPECT_EQ(c1.model, "PINHOLE");
  EXPECT_EQ(c1.width, 640u);
  EXPECT_EQ(c1.height, 480u);
  EXPECT_EQ(c1.params, (std::vector<double>{500.5, 501.25, 320, 240.5}));
  const ColmapCamera& c3 = m.cameras.at(3);
  EXPECT_EQ(c3.model, "SIMPLE_RADIAL");  // distorted models are read as they are
  EXPECT_EQ(c3.params, (std::vector<double>{1400, 960, 540, -0.0125}));

  ASSERT_EQ(m.images.size(), 2u);
  const ColmapImage& i1 = m.images.at(1);
  EXPECT_EQ(i1.q.w(), 0.5);
  EXPECT_EQ(i1.q.x(), 0.5);
  EXPECT_EQ(i1.q.y(), -0.5);
  EXPECT_EQ(i1.q.z(), 0.5);
  EXPECT_EQ(i1.t, Eigen::Vector3d(1.5, -2, 3.25));
  EXPECT_EQ(i1.camera_id, 1u);
  EXPECT_EQ(i1.name, "left/0001.png");
  ASSERT_EQ(i1.xys.size(), 3u);
  EXPECT_EQ(i1.xys[0], Eigen::Vector2d(10.5, 20.25));
  EXPECT_EQ(i1.xys[1], Eigen::Vector2d(300, 400));
  EXPECT_EQ(i1.xys[2], Eigen::Vector2d(33.125, 44));
  EXPECT_EQ(i1.point3d_ids, (std::vector<std::uint64_t>{7, kInvalidPoint3DId, 8}));
  const ColmapImage& i2 = m.images.at(2);
  EXPECT_EQ(i2.q.w(), 1.0);
  EXPECT_EQ(i2.t.z(), 1e-3);
  EXPECT_EQ(i2.camera_id, 3u);
  EXPECT_EQ(i2.name, "0002.png");
  EXPECT_TRUE(i2.xys.empty());
  EXPECT_TRUE(i2.point3d_ids.empty());

  ASSERT_EQ(m.points.size(), 2u);
  const ColmapPoint3D& p7 = m.points.at(7);
  EXPECT_EQ(p7.xyz, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(p7.rgb, (std::array<std::uint8_t, 3>{255, 128, 0}));
  EXPECT_EQ(p7.error, 0.5);
  EXPECT_EQ(p7.track, (std::vector<TrackElement>{{1, 0}}));
  const ColmapPoint3D& p8 = m.points.at(8);
  EXPECT_EQ(p8.xyz, Eigen::Vector3d(-1.5, 0.25, 1000));
  EXPECT_EQ(p8.rgb, (std::array<std::uint8_t, 3>{10, 20, 30}));
  EXPECT_EQ(p8.error, 1.25);
  EXPECT_EQ(p8.track, (std::vector<TrackElement>{{1, 2}}));
}

TEST(ColmapIo, TextAcceptsCrlfAndMissingLastEmptyLine) {
  TempDir dir;
  writeText(dir, "# c\r\n1 SIMPLE_PINHOLE 10 20 5 5 10\r\n",
            "1 1 0 0 0 0 0 0 1 my image.png\r\n1 2 -1\r\n2 1 0 0 0 0 0 0 1 b.png", "");
  const ColmapModel m = readColmapModel(dir.str());
  ASSERT_EQ(m.images.size(), 2u);
  EXPECT_EQ(m.images.at(1).name, "my image.png");
  EXPECT_EQ(m.images.at(1).xys.size(), 1u);
  EXPECT_EQ(m.images.at(2).name, "b.png");
  EXPECT_TRUE(m.images.at(2).xys.empty());
}

// ---- Malformed input: every case must be an InputError naming file and field.

TEST(ColmapErrors, MissingFile) {
  TempDir dir;
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, dir.str(), "model"));
  writeBytes(dir.file("cameras.txt"), kCameras);
  writeBytes(dir.file("images.txt"), kImages);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "points3D.txt", "file"));
  writeColmapBinary(dir.str(), tinyModel());
  fs::remove(dir.file("images.bin"));
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "images.bin", "file"));
  EXPECT_TRUE(throwsInputError([&] { readColmapText(dir.file("nothing")); }, "cameras.txt", "file"));
}

TEST(ColmapErrors, TruncatedBinaryAtEveryOffset) {
  TempDir dir;
  writeColmapBinary(dir.file("good"), tinyModel());
  for (const std::string name : {"cameras.bin", "images.bin", "points3D.bin"}) {
    const std::string full = readBytes(dir.file("good/" + name));
    ASSERT_GT(full.size(), 20u);
    for (size_t len = 0; len < full.size(); ++len) {
      SCOPED_TRACE(name + " truncated to " + std::to_string(len) + " bytes");
      writeColmapBinary(dir.file("bad"), tinyModel());
      writeBytes(dir.file("bad/" + name), full.substr(0, len));
      try {
        readColmapModel(dir.file("bad"));
        ADD_FAILURE() << "read a truncated file";
      } catch (const InputError& e) {
        EXPECT_EQ(e.file(), dir.file("bad/" + name));
        EXPECT_FALSE(e.field().empty());
      }
    }
  }
}

TEST(ColmapErrors, TextCountDoesNotParse) {
  TempDir dir;
  writeText(dir, "# Number of cameras: three\n" + kCameras, kImages, kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapText(dir.str()); }, "cameras.txt", "line 1: Number of cameras"));
}

TEST(ColmapErrors, TextCountDisagreesWithRecords) {
  TempDir dir;
  writeColmapText(dir.str(), randomColmapModel(7));
  // Drop the last point line, as a truncated copy would.
  std::string points = readBytes(dir.file("points3D.txt"));
  points.erase(points.rfind('\n', points.size() - 2) + 1);
  writeBytes(dir.file("points3D.txt"), points);
  EXPECT_TRUE(throwsInputError([&] { readColmapText(dir.str()); }, "points3D.txt", "Number of points"));
}

TEST(ColmapErrors, BinaryCountLargerThanData) {
  TempDir dir;
  writeColmapBinary(dir.str(), tinyModel());
  patch<std::uint64_t>(dir.file("cameras.bin"), 0, 1000000000000ull);
  EXPECT_TRUE(throwsInputError([&] { readColmapBinary(dir.str()); }, "cameras.bin", "num_cameras"));

  writeColmapBinary(dir.str(), tinyModel());
  patch<std::uint64_t>(dir.file("cameras.bin"), 0, 2);  // one camera of 56 bytes follows
  EXPECT_TRUE(throwsInputError([&] { readColmapBinary(dir.str()); }, "cameras.bin", "num_cameras"));

  writeColmapBinary(dir.str(), tinyModel());
  const size_t num_points2d = 8 + 4 + 7 * 8 + 4 + std::string("a.png").size() + 1;
  patch<std::uint64_t>(dir.file("images.bin"), num_points2d, std::numeric_limits<std::uint64_t>::max());
  EXPECT_TRUE(throwsInputError([&] { readColmapBinary(dir.str()); }, "images.bin", "image 1: num_points2D"));

  writeColmapBinary(dir.str(), tinyModel());
  patch<std::uint64_t>(dir.file("points3D.bin"), 8 + 8 + 3 * 8 + 3 + 8, 1ull << 40);
  EXPECT_TRUE(throwsInputError([&] { readColmapBinary(dir.str()); }, "points3D.bin", "point 1: track_length"));
}

TEST(ColmapErrors, BinaryCountSmallerThanData) {
  TempDir dir;
  ColmapModel m = tinyModel();
  addCamera(m, 2, "PINHOLE", 64, 48, {50, 51, 32, 24});
  writeColmapBinary(dir.str(), m);
  patch<std::uint64_t>(dir.file("cameras.bin"), 0, 1);
  EXPECT_TRUE(throwsInputError([&] { readColmapBinary(dir.str()); }, "cameras.bin", "end of file"));
}

TEST(ColmapErrors, NanOrInfInPose) {
  TempDir dir;
  writeText(dir, kCameras, "1 nan 0 0 0 0 0 0 1 a.png\n\n", kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "images.txt", "line 1: quaternion"));
  writeText(dir, kCameras, "# c\n1 1 0 0 0 0 inf 0 1 a.png\n\n", kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "images.txt", "line 2: translation"));

  ColmapModel m = tinyModel();
  m.images[1].q.x() = std::numeric_limits<double>::quiet_NaN();
  writeColmapBinary(dir.str(), m);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "images.bin", "image 1: quaternion"));
  m = tinyModel();
  m.images[1].t.z() = -std::numeric_limits<double>::infinity();
  writeColmapBinary(dir.str(), m);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "images.bin", "image 1: translation"));
}

TEST(ColmapErrors, NanOrInfInPoint) {
  TempDir dir;
  writeText(dir, kCameras, "1 1 0 0 0 0 0 0 1 a.png\n10 20 4\n", "4 1 NaN 3 0 0 0 0.5 1 0\n");
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "points3D.txt", "line 1: xyz"));
  writeText(dir, kCameras, "1 1 0 0 0 0 0 0 1 a.png\n10 inf -1\n", "");
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "images.txt", "line 2: points2D"));

  ColmapModel m = tinyModel();
  m.points[1].xyz.y() = std::numeric_limits<double>::infinity();
  writeColmapBinary(dir.str(), m);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "points3D.bin", "point 1: xyz"));
}

TEST(ColmapErrors, NonUnitQuaternion) {
  TempDir dir;
  writeText(dir, kCameras, "1 1.002 0 0 0 0 0 0 1 a.png\n\n", kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "images.txt", "line 1: quaternion"));
  writeText(dir, kCameras, "1 0 0 0 0 0 0 0 1 a.png\n\n", kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "images.txt", "line 1: quaternion"));
  // Within the 1e-3 tolerance: rounding in other tools must not be refused.
  writeText(dir, kCameras, "1 0.9995 0 0 0 0 0 0 1 a.png\n\n", kPoints);
  EXPECT_NO_THROW(readColmapModel(dir.str()));

  ColmapModel m = tinyModel();
  m.images[1].q = Eigen::Quaterniond(0.5, 0.5, 0.5, 0.4);
  writeColmapBinary(dir.str(), m);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "images.bin", "image 1: quaternion"));
  m.images[1].q = Eigen::Quaterniond(0, 0, 0, 0);
  writeColmapBinary(dir.str(), m);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "images.bin", "image 1: quaternion"));
}

TEST(ColmapErrors, UnknownCameraModel) {
  TempDir dir;
  writeText(dir, "1 PINHOLE_X 640 480 500 500 320 240\n", kImages, kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "cameras.txt", "line 1: model"));

  writeColmapBinary(dir.str(), tinyModel());
  patch<std::int32_t>(dir.file("cameras.bin"), 8 + 4, 42);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "cameras.bin", "camera 1: model_id"));
  patch<std::int32_t>(dir.file("cameras.bin"), 8 + 4, -1);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "cameras.bin", "camera 1: model_id"));
}

TEST(ColmapErrors, WrongParameterCount) {
  TempDir dir;
  writeText(dir, "1 PINHOLE 640 480 500 320 240\n", kImages, kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "cameras.txt", "line 1: params"));
  writeText(dir, "1 OPENCV 640 480 500 500 320 240 0 0 0 0 0\n", kImages, kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "cameras.txt", "line 1: params"));
}

TEST(ColmapErrors, NonPositiveFocalLengthOrSize) {
  TempDir dir;
  writeText(dir, "1 SIMPLE_PINHOLE 640 480 0 320 240\n", kImages, kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "cameras.txt", "line 1: focal length"));
  writeText(dir, "1 PINHOLE 640 480 500 -500 320 240\n", kImages, kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "cameras.txt", "line 1: focal length"));
  writeText(dir, "1 OPENCV 640 480 -1 500 320 240 0 0 0 0\n", kImages, kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "cameras.txt", "line 1: focal length"));
  writeText(dir, "1 PINHOLE 0 480 500 500 320 240\n", kImages, kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "cameras.txt", "line 1: width"));
  writeText(dir, "1 PINHOLE 640 0 500 500 320 240\n", kImages, kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "cameras.txt", "line 1: height"));
  writeText(dir, "1 PINHOLE -640 480 500 500 320 240\n", kImages, kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "cameras.txt", "line 1: WIDTH"));

  ColmapModel m = tinyModel();
  m.cameras[1].width = 0;
  writeColmapBinary(dir.str(), m);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "cameras.bin", "camera 1: width"));
  m = tinyModel();
  m.cameras[1].params[1] = -2;
  writeColmapBinary(dir.str(), m);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "cameras.bin", "camera 1: focal length"));
}

TEST(ColmapErrors, ImageReferencesMissingCamera) {
  TempDir dir;
  writeText(dir, kCameras, "1 1 0 0 0 0 0 0 1 a.png\n\n2 1 0 0 0 0 0 0 5 b.png\n\n", kPoints);
  EXPECT_NO_THROW(readColmapText(dir.str()));  // the per-file reader does not cross-check
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, dir.str(), "image 2: camera_id"));
  ColmapModel m = tinyModel();
  m.images[1].camera_id = 3;
  EXPECT_TRUE(throwsInputError([&] { validateColmapModel(m, "somewhere"); }, "somewhere", "image 1: camera_id"));
}

TEST(ColmapErrors, ImageReferencesMissingPoint) {
  TempDir dir;
  writeText(dir, kCameras, "1 1 0 0 0 0 0 0 1 a.png\n10 20 -1 30 40 12\n", kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, dir.str(), "image 1: point3D_id"));
  ColmapModel m = tinyModel();
  m.images[1].point3d_ids[1] = 99;
  writeColmapBinary(dir.str(), m);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, dir.str(), "image 1: point3D_id"));
}

TEST(ColmapErrors, TrackReferencesMissingImage) {
  TempDir dir;
  writeText(dir, kCameras, kImages, "12 1 2 3 0 0 0 0.5 1 0 4 0\n");
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, dir.str(), "point 12: track"));
}

TEST(ColmapErrors, TrackIndexOutOfRange) {
  TempDir dir;
  writeText(dir, kCameras, kImages, "12 1 2 3 0 0 0 0.5 1 1\n");
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, dir.str(), "point 12: track"));
  ColmapModel m = tinyModel();
  m.points[1].track.push_back({1, 2});
  writeColmapBinary(dir.str(), m);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, dir.str(), "point 1: track"));
}

TEST(ColmapErrors, TextValuesThatDoNotParse) {
  TempDir dir;
  writeText(dir, kCameras, "# a\n\n# b\n1 1 0 0 0 0 0 0 1 a.png\n\n2 x 0 0 0 0 0 0 1 b.png\n\n", kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "images.txt", "line 6: QW"));
  writeText(dir, kCameras, "1 1 0 0 0 0 0 0\n\n", kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "images.txt", "line 1: CAMERA_ID"));
  writeText(dir, kCameras, "1 1 0 0 0 0 0 0 1\n\n", kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "images.txt", "line 1: NAME"));
  writeText(dir, kCameras, "1 1 0 0 0 0 0 0 1 a.png\n10 20\n", kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "images.txt", "line 2: POINTS2D"));
  writeText(dir, kCameras, "1 1 0 0 0 0 0 0 1 a.png\n10 20 -2\n", kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "images.txt", "line 2: POINT3D_ID"));
  writeText(dir, kCameras, "1 1 0 0 0 0 0 0 1 a.png\n1 1 0 0 0 0 0 0 1 b.png\n\n", kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "images.txt", "line 2: POINTS2D"));
  writeText(dir, "-1 PINHOLE 640 480 500 500 320 240\n", kImages, kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "cameras.txt", "line 1: CAMERA_ID"));
  writeText(dir, "1 PINHOLE 640 480 500 500 320 240x\n", kImages, kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "cameras.txt", "line 1: PARAMS"));
  writeText(dir, kCameras, "1 1 0 0 0 0 0 0 1 a.png\n10 20 4\n", "4 1 2 3 256 0 0 0.5 1 0\n");
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "points3D.txt", "line 1: R"));
  writeText(dir, kCameras, "1 1 0 0 0 0 0 0 1 a.png\n10 20 4\n", "4 1 2 3 0 0 0 0.5 1\n");
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "points3D.txt", "line 1: TRACK"));
}

TEST(ColmapErrors, DuplicateIds) {
  TempDir dir;
  writeText(dir, kCameras + kCameras, kImages, kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "cameras.txt", "line 2: CAMERA_ID"));
  writeText(dir, kCameras, kImages + kImages, kPoints);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "images.txt", "line 3: IMAGE_ID"));

  ColmapModel m = tinyModel();
  m.points[2] = m.points[1];
  m.points[2].id = 2;
  writeColmapBinary(dir.str(), m);
  patch<std::uint64_t>(dir.file("points3D.bin"), 8 + 59, 1);  // second point's id := 1
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "points3D.bin", "point record 1: point3D_id"));
}

TEST(ColmapErrors, BinaryNegativePointId) {
  TempDir dir;
  writeColmapBinary(dir.str(), tinyModel());
  const size_t first_id = 8 + 4 + 7 * 8 + 4 + std::string("a.png").size() + 1 + 8 + 16;
  patch<std::int64_t>(dir.file("images.bin"), first_id, -2);
  EXPECT_TRUE(throwsInputError([&] { readColmapModel(dir.str()); }, "images.bin", "image 1: point3D_id"));
}

TEST(ColmapErrors, ValidateChecksRecordsBuiltInCode) {
  ColmapModel m = tinyModel();
  EXPECT_NO_THROW(validateColmapModel(m, "dir"));
  m.cameras[1].id = 2;
  EXPECT_TRUE(throwsInputError([&] { validateColmapModel(m, "dir"); }, "dir", "camera 1: camera_id"));
  m = tinyModel();
  m.images[1].point3d_ids.pop_back();
  EXPECT_TRUE(throwsInputError([&] { validateColmapModel(m, "dir"); }, "dir", "image 1: points2D"));
  m = tinyModel();
  m.cameras[1].model = "PINHOLE ";
  EXPECT_TRUE(throwsInputError([&] { validateColmapModel(m, "dir"); }, "dir", "camera 1: model"));
}

TEST(ColmapErrors, WritersRefuseWhatTheFormatCannotHold) {
  TempDir dir;
  ColmapModel m = tinyModel();
  m.cameras[1].model = "FISHEYE_9000";
  EXPECT_TRUE(throwsInputError([&] { writeColmapBinary(dir.str(), m); }, "cameras.bin", "camera 1: model"));
  m = tinyModel();
  m.cameras[1].params.pop_back();
  EXPECT_TRUE(throwsInputError([&] { writeColmapBinary(dir.str(), m); }, "cameras.bin", "camera 1: params"));
  m = tinyModel();
  m.images[1].name = "two\nlines.png";
  EXPECT_TRUE(throwsInputError([&] { writeColmapText(dir.str(), m); }, "images.txt", "image 1: name"));
  EXPECT_TRUE(fs::is_empty(dir.str()));  // nothing half-written
}
