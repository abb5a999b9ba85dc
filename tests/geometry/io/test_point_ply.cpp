// points3d.ply: written as 3DGS writes it, read back; bad files are refused by field.
#include <gtest/gtest.h>

#include "common/test_support.h"
#include "geometry/io/point_ply.h"

using namespace saresgs;

TEST(PointPly, RoundTripAndAscii) {
  test::TempDir d;
  std::vector<PlyPoint> pts{{Eigen::Vector3d(0.5, -1.25, 3), {1, 2, 3}}, {Eigen::Vector3d(-7, 0, 1e-3), {255, 0, 128}}};
  writePointsPly(d.file("p.ply"), pts);
  const std::vector<PlyPoint> back = readPointsPly(d.file("p.ply"));
  ASSERT_EQ(back.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back[i].xyz, pts[i].xyz.cast<float>().cast<double>());
    EXPECT_EQ(back[i].rgb, pts[i].rgb);
  }
  // ASCII, double coordinates, no colour (grey), a face element after the vertices.
  test::writeBytes(d.file("a.ply"),
                   "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\nproperty double y\nproperty double z\n"
                   "property float quality\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n"
                   "1 2 3 0.5\n-4 5.5 6e-1 1\n");
  const std::vector<PlyPoint> a = readPointsPly(d.file("a.ply"));
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a[1].xyz, Eigen::Vector3d(-4, 5.5, 0.6));
  EXPECT_EQ(a[1].rgb, (std::array<std::uint8_t, 3>{128, 128, 128}));
}

TEST(PointPly, BadFilesNameTheField) {
  test::TempDir d;
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  test::writeBytes(d.file("nan.ply"), head + "1 nan 3\n");
  EXPECT_TRUE(test::throwsInputError([&] { readPointsPly(d.file("nan.ply")); }, "nan.ply", "vertex 0"));
  test::writeBytes(d.file("inf.ply"), head + "1 2 inf\n");
  EXPECT_TRUE(test::throwsInputError([&] { readPointsPly(d.file("inf.ply")); }, "inf.ply", "vertex 0"));
  test::writeBytes(d.file("short.ply"), head + "1 2\n");
  EXPECT_TRUE(test::throwsInputError([&] { readPointsPly(d.file("short.ply")); }, "short.ply", "vertex"));
  // A count the file cannot hold is refused before anything is allocated.
  test::writeBytes(
      d.file("huge.ply"),
      "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000000\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n0123456789ab");
  EXPECT_TRUE(test::throwsInputError([&] { readPointsPly(d.file("huge.ply")); }, "huge.ply", "element vertex"));
  test::writeBytes(d.file("nox.ply"),
                   "ply\nformat ascii 1.0\nelement vertex 1\nproperty float y\nproperty float z\nend_header\n1 2\n");
  EXPECT_TRUE(test::throwsInputError([&] { readPointsPly(d.file("nox.ply")); }, "nox.ply", "property x"));
  test::writeBytes(d.file("be.ply"), "ply\nformat binary_big_endian 1.0\nelement vertex 0\nend_header\n");
  EXPECT_TRUE(test::throwsInputError([&] { readPointsPly(d.file("be.ply")); }, "be.ply", "format"));
  test::writeBytes(d.file("rgb.ply"),
                   "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
                   "property float red\nend_header\n1 2 3 0.5\n");
  EXPECT_TRUE(test::throwsInputError([&] { readPointsPly(d.file("rgb.ply")); }, "rgb.ply", "property red"));
}
