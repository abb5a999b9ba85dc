#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>

#include "geometry/error.h"
#include "geometry/synth/procedural_meshes.h"
#include "geometry/synth/texture.h"

using namespace saresgs;
using namespace saresgs::synth;

namespace {

constexpr double kPi = std::numbers::pi;

// Signed volume by the divergence theorem: positive for closed outward meshes.
double signedVolume(const TriangleMesh& m) {
  double v = 0;
  for (const auto& f : m.faces)
    v += m.vertices[f[0]].cast<double>().dot(m.vertices[f[1]].cast<double>().cross(m.vertices[f[2]].cast<double>())) /
         6.0;
  return v;
}

// Every edge of a closed, consistently oriented mesh is used once in each direction.
bool closedAndConsistent(const TriangleMesh& m) {
  std::map<std::pair<int, int>, int> count;
  for (const auto& f : m.faces)
    for (int k = 0; k < 3; ++k) ++count[{f[k], f[(k + 1) % 3]}];
  for (const auto& [e, c] : count) {
    if (c != 1) return false;
    auto it = count.find({e.second, e.first});
    if (it == count.end() || it->second != 1) return false;
  }
  return true;
}

}  // namespace

TEST(ProceduralMeshes, VolumesMatchTheAnalyticShapes) {
  // Inscribed tessellations are slightly smaller than the true shapes.
  EXPECT_NEAR(signedVolume(makeSphere(1.5f, 128, 64)), 4.0 / 3.0 * kPi * std::pow(1.5, 3), 0.01 * 14.1);
  EXPECT_NEAR(signedVolume(makeBox({-1, -2, -3}, {1, 2, 3}, 3)), 2 * 4 * 6, 1e-4);
  EXPECT_NEAR(signedVolume(makeCylinder(0.5f, 2.0f, 128)), kPi * 0.25 * 2.0, 0.005);
  EXPECT_NEAR(signedVolume(makeCone(0.5f, 2.0f, 128)), kPi * 0.25 * 2.0 / 3.0, 0.003);
  EXPECT_NEAR(signedVolume(makeTorus(1.0f, 0.25f, 128, 64)), 2 * kPi * kPi * 1.0 * 0.0625, 0.01);
  EXPECT_GT(signedVolume(makeSuperquadric({1, 0.8f, 0.6f}, 0.5f, 0.5f)), 0.0);
  EXPECT_GT(signedVolume(makeBumpyBlob(1.0f, 0.2f, 2.0f, 7)), 0.0);
}

TEST(ProceduralMeshes, SmoothShapesAreClosedAndConsistentlyOriented) {
  EXPECT_TRUE(closedAndConsistent(makeSphere(1.0f, 32, 16)));
  EXPECT_TRUE(closedAndConsistent(makeTorus(1.0f, 0.3f, 32, 16)));
  EXPECT_TRUE(closedAndConsistent(makeSuperquadric({1, 1, 1}, 0.3f, 0.3f, 32, 16)));
  EXPECT_TRUE(closedAndConsistent(makeBumpyBlob(1.0f, 0.3f, 2.0f, 3, 32, 16)));
}

TEST(ProceduralMeshes, SphereNormalsPointOutwardAndRadially) {
  const TriangleMesh s = makeSphere(2.0f, 64, 32);
  const auto n = vertexNormals(s);
  for (std::size_t i = 0; i < s.vertices.size(); ++i) EXPECT_GT(n[i].dot(s.vertices[i].normalized()), 0.999f) << i;
}

TEST(ProceduralMeshes, BoxNormalsStayFlatAtEdges) {
  const TriangleMesh b = makeBox({0, 0, 0}, {1, 1, 1}, 2);
  const auto n = vertexNormals(b);
  for (const auto& v : n) EXPECT_NEAR(v.cwiseAbs().maxCoeff(), 1.0f, 1e-6f);
  EXPECT_NEAR(surfaceArea(b), 6.0, 1e-5);
}

TEST(ProceduralMeshes, RoomFacesPointInward) {
  const RoomFaces r = makeRoom({-4, -4, 0}, {4, 4, 4});
  auto faceNormal = [](const TriangleMesh& m) {
    const auto& f = m.faces[0];
    return Eigen::Vector3f(
        (m.vertices[f[1]] - m.vertices[f[0]]).cross(m.vertices[f[2]] - m.vertices[f[0]]).normalized());
  };
  EXPECT_GT(faceNormal(r.floor).z(), 0.99f);
  EXPECT_LT(faceNormal(r.ceiling).z(), -0.99f);
  EXPECT_GT(faceNormal(r.wall_xlo).x(), 0.99f);
  EXPECT_LT(faceNormal(r.wall_xhi).x(), -0.99f);
  EXPECT_GT(faceNormal(r.wall_ylo).y(), 0.99f);
  EXPECT_LT(faceNormal(r.wall_yhi).y(), -0.99f);
  EXPECT_NEAR(surfaceArea(r.floor), 64.0, 1e-4);
  EXPECT_NEAR(surfaceArea(r.wall_xhi), 32.0, 1e-4);
}

TEST(ProceduralMeshes, NormaliseCentresAndScales) {
  TriangleMesh m = makeBox({2, 3, 4}, {4, 5, 8});
  normaliseMesh(m, 1.0f);
  const auto box = boundingBox(m);
  EXPECT_LT(box.center().norm(), 1e-5f);
  float r = 0;
  for (const auto& v : m.vertices) r = std::max(r, v.norm());
  EXPECT_NEAR(r, 1.0f, 1e-5f);
}

TEST(ProceduralMeshes, UpAxisRotationTakesTheAxisToZ) {
  EXPECT_TRUE((upAxisRotation("y") * Eigen::Vector3f::UnitY()).isApprox(Eigen::Vector3f::UnitZ()));
  EXPECT_TRUE((upAxisRotation("x") * Eigen::Vector3f::UnitX()).isApprox(Eigen::Vector3f::UnitZ()));
  EXPECT_TRUE(upAxisRotation("z").isIdentity());
  for (const char* a : {"x", "y"}) EXPECT_NEAR(upAxisRotation(a).determinant(), 1.0f, 1e-6f);
  EXPECT_THROW(upAxisRotation("w"), InputError);
}

TEST(Textures, BilinearSamplingInterpolatesAndWraps) {
  ImageF img(2, 1, 3, 0.0f);
  img.at(1, 0, 0) = 1.0f;  // red channel: 0 at x = 0.5, 1 at x = 1.5
  EXPECT_NEAR(sampleBilinear(img, 0.5f, 0.5f, true).x(), 0.0f, 1e-6f);
  EXPECT_NEAR(sampleBilinear(img, 1.5f, 0.5f, true).x(), 1.0f, 1e-6f);
  EXPECT_NEAR(sampleBilinear(img, 1.0f, 0.5f, true).x(), 0.5f, 1e-6f);
  EXPECT_NEAR(sampleBilinear(img, 2.0f, 0.5f, true).x(), 0.5f, 1e-6f);  // wraps to x = 0
  EXPECT_NEAR(sampleBilinear(img, 2.5f, 0.5f, true).x(), 0.0f, 1e-6f);
  EXPECT_NEAR(sampleBilinear(img, -0.5f, 0.5f, true).x(), 1.0f, 1e-6f);
}

TEST(Textures, ProceduralTexturesStayInRangeAndVary) {
  const std::vector<std::shared_ptr<Texture>> all = {
      makeChecker(0.3f, rgb(255, 255, 0), rgb(0, 0, 255), 1),
      makeStripes({1, 0, 0}, 0.2f, rgb(255, 0, 0), rgb(0, 255, 0), rgb(0, 0, 255), 2),
      makeMarble(1.0f, rgb(230, 230, 230), rgb(20, 20, 20), 3),
      makeWood({0, 0, 1}, {0.5f, 0, 0}, 0.1f, rgb(220, 180, 120), rgb(100, 60, 30), 4),
      makePlanks(0.2f, 1.0f, rgb(220, 180, 120), rgb(100, 60, 30), 5),
      makeBricks(0.25f, 0.1f, 0.02f, rgb(170, 70, 50), rgb(200, 200, 200), 6),
      makeTiles(0.4f, 0.03f, rgb(60, 100, 200), rgb(240, 240, 240), rgb(90, 90, 90), 7),
      makeSpeckle(1.0f, rgb(230, 230, 220), rgb(100, 100, 100), 8),
      makeDots(0.3f, 0.1f, rgb(240, 240, 240), rgb(200, 0, 0), 9)};
  for (const auto& t : all) {
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(1), hi = Eigen::Vector3f::Zero();
    for (int i = 0; i < 1600; ++i) {
      // A 40 x 40 grid on the plane z = 1 (normal +z) and on x = 1 (normal +x).
      const float a = 0.031f * (i % 40), b = 0.029f * (i / 40);
      for (const auto& [p, n] : {std::pair{Eigen::Vector3f(a, b, 1), Eigen::Vector3f::UnitZ().eval()},
                                 std::pair{Eigen::Vector3f(1, a, b), Eigen::Vector3f::UnitX().eval()}}) {
        const Eigen::Vector3f c = t->albedo(p, n);
        ASSERT_TRUE(c.allFinite()) << t->describe();
        ASSERT_GE(c.minCoeff(), 0.0f) << t->describe();
        ASSERT_LE(c.maxCoeff(), 1.0f) << t->describe();
        lo = lo.cwiseMin(c);
        hi = hi.cwiseMax(c);
      }
    }
    EXPECT_GT((hi - lo).maxCoeff(), 0.15f) << t->describe() << " looks flat";
    EXPECT_EQ(t->describe().rfind("procedural:", 0), 0u);
  }
}
