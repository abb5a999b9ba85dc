#include <gtest/gtest.h>

#include <fstream>

#include "common/test_support.h"
#include "geometry/error.h"
#include "geometry/synth/mesh.h"

using namespace saresgs;

TEST(MeshIO, ReadsOffAndObjWithPolygonsAsFans) {
  test::TempDir d;
  std::ofstream(d.file("quad.off")) << "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
  const TriangleMesh off = readMeshFile(d.file("quad.off"));
  ASSERT_EQ(off.vertices.size(), 4u);
  ASSERT_EQ(off.faces.size(), 2u);
  EXPECT_EQ(off.faces[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(off.faces[1], Eigen::Vector3i(0, 2, 3));
  EXPECT_EQ(off.vertices[2], Eigen::Vector3f(1, 1, 0));

  std::ofstream(d.file("tri.obj")) << "v 0 0 0\nv 2 0 0\nv 0 3 0\nf 1 2 3\n";
  const TriangleMesh obj = readMeshFile(d.file("tri.obj"));
  ASSERT_EQ(obj.faces.size(), 1u);
  EXPECT_EQ(obj.vertices[2], Eigen::Vector3f(0, 3, 0));
}

TEST(MeshIO, BadFilesNameTheFile) {
  test::TempDir d;
  auto expectError = [&](const std::string& name, const std::string& field) {
    EXPECT_TRUE(test::throwsInputError([&] { readMeshFile(d.file(name)); }, name, field));
  };
  expectError("missing.off", "file");
  std::ofstream(d.file("garbage.off")) << "this is not a mesh\n";
  expectError("garbage.off", "file");
  std::ofstream(d.file("points.off")) << "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n";
  expectError("points.off", "faces");
}
