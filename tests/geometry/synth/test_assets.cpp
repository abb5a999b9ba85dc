#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "common/test_support.h"
#include "geometry/error.h"
#include "geometry/synth/assets.h"
#include "geometry/synth/mesh.h"

using namespace saresgs;

TEST(Assets, CgalMeshIsExtractedIntoTheCacheAndReadable) {
  test::TempDir d;
  ::setenv("SARESGS_DATA_CACHE", d.str().c_str(), 1);
  const std::string path = resolveAsset("cgal:bunny00");
  EXPECT_EQ(path.rfind(d.str(), 0), 0u) << path;
  const TriangleMesh m = readMeshFile(path);
  EXPECT_GT(m.faces.size(), 1000u);               // the Stanford bunny, not a placeholder
  EXPECT_EQ(resolveAsset("cgal:bunny00"), path);  // cached
  EXPECT_THROW(resolveAsset("cgal:no_such_mesh"), InputError);
  EXPECT_THROW(resolveAsset("cgal:../etc/passwd"), InputError);
  ::unsetenv("SARESGS_DATA_CACHE");
}

TEST(Assets, OpencvPhotographsAndPlainPaths) {
  EXPECT_TRUE(std::filesystem::exists(resolveAsset("opencv:baboon.jpg")));
  EXPECT_THROW(resolveAsset("opencv:nothing.png"), InputError);
  EXPECT_EQ(resolveAsset("some/file.off"), "some/file.off");
}
