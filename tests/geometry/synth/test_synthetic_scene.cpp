#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <map>
#include <random>
#include <set>

#include "geometry/error.h"
#include "geometry/synth/procedural_meshes.h"
#include "geometry/synth/ray_tracer.h"
#include "geometry/synth/render_detail.h"
#include "geometry/synth/assets.h"
#include "geometry/synth/synthetic_scene.h"
#include "tests/geometry/synth/synth_test_support.h"

using namespace saresgs;
using namespace saresgs::synth_test;

namespace {

std::string tempPath(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / "saresgs_test_synth";
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

Eigen::Vector3f pixel(const ImageF& img, int x, int y) { return {img.at(x, y, 0), img.at(x, y, 1), img.at(x, y, 2)}; }

double meanAbsDiff(const ImageF& a, const ImageF& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.data.size(); ++i) s += std::abs(a.data[i] - b.data[i]);
  return s / static_cast<double>(a.data.size());
}

}  // namespace

// ------------------------------------------------------------------ ray tracer

TEST(RayTracer, SphereHitsMatchAnalyticIntersection) {
  const float R = 1.0f;
  const TriangleMesh sphere = synth::makeSphere(R, 256, 128);
  synth::RayTracer tracer({&sphere});
  std::mt19937_64 rng(11);
  std::normal_distribution<float> n(0, 1);
  std::uniform_real_distribution<float> u(0, 1);
  auto randomDir = [&] { return Eigen::Vector3f(n(rng), n(rng), n(rng)).normalized(); };
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3f o = randomDir() * (2.0f + 3.0f * u(rng));
    // Aim at a point inside radius 0.9: the ray must hit.
    const Eigen::Vector3f aim = randomDir() * 0.9f * std::cbrt(u(rng));
    const Eigen::Vector3f d = (aim - o).normalized();
    // Analytic: |o + t d|^2 = R^2, nearest root.
    const float b = o.dot(d), c = o.squaredNorm() - R * R;
    const float t_exact = -b - std::sqrt(b * b - c);
    const synth::TraceHit h = tracer.intersect(o, d);
    ASSERT_TRUE(h.hit) << i;
    EXPECT_EQ(h.object, 0);
    // The tessellation lies inside the sphere by at most ~R(1 - cos(pi/128)) ~ 3e-4 R
    // radially; along a ray at least 26 degrees off tangent that stays below 1e-3.
    EXPECT_GE(h.t, t_exact - 1e-4f) << i;
    EXPECT_NEAR(h.t, t_exact, 1e-3f) << i;
    ++hits;
  }
  EXPECT_EQ(hits, 2000);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3f o = randomDir() * (2.0f + 3.0f * u(rng));
    // A direction whose line passes the centre at distance 1.01..1.9: it misses.
    const Eigen::Vector3f to_c = -o.normalized();
    Eigen::Vector3f side = randomDir();
    side = (side - side.dot(to_c) * to_c).normalized();
    const float miss = std::min(1.01f + 0.9f * u(rng), 0.95f * o.norm());
    const float sin_a = miss / o.norm();
    const Eigen::Vector3f d = (to_c * std::sqrt(1 - sin_a * sin_a) + side * sin_a).normalized();
    const float closest = (o - o.dot(d) * d).norm();
    ASSERT_GT(closest, R);
    EXPECT_FALSE(tracer.intersect(o, d).hit) << i;
    EXPECT_FALSE(tracer.occluded(o, d, 0, 100)) << i;
  }
}

TEST(RayTracer, RespectsTheRayIntervalAndMapsObjectIds) {
  const TriangleMesh a = synth::makeBox({-1, -1, -1}, {1, 1, 1});
  const TriangleMesh b = synth::makeBox({4, -1, -1}, {6, 1, 1});
  synth::RayTracer tracer({&a, &b}, {7, 3});
  const Eigen::Vector3f o(-5, 0, 0), d(1, 0, 0);
  auto h = tracer.intersect(o, d);
  ASSERT_TRUE(h.hit);
  EXPECT_EQ(h.object, 7);
  EXPECT_NEAR(h.t, 4.0f, 1e-5f);
  h = tracer.intersect(o, d, 6.5f);  // past the first box's far side: the second box
  ASSERT_TRUE(h.hit);
  EXPECT_EQ(h.object, 3);
  EXPECT_NEAR(h.t, 9.0f, 1e-5f);
  EXPECT_FALSE(tracer.intersect(o, d, 0, 3.9f).hit);
  EXPECT_TRUE(tracer.occluded(o, d, 0, 4.1f));
  EXPECT_FALSE(tracer.occluded(o, d, 0, 3.9f));
  // A non-unit direction: t is in units of the direction.
  h = tracer.intersect(o, 2.0f * d);
  EXPECT_NEAR(h.t, 2.0f, 1e-5f);
}

// ------------------------------------------------------------------ scene queries

TEST(SyntheticScene, IntersectReportsDistanceAlongTheUnitDirectionAndFacingNormals) {
  const SyntheticScene& s = scene("room360");
  const Eigen::Vector3f o(0.5f, -3.0f, 2.0f);
  const Eigen::Vector3f d(0, 0, 1);  // straight up to the ceiling at z = 4
  SurfaceHit h = s.intersect(o, d);
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.distance, 2.0f, 1e-4f);
  EXPECT_NEAR(h.normal.z(), -1.0f, 1e-5f);
  EXPECT_EQ(s.objectNames()[h.object], "room_ceiling");
  h = s.intersect(o, 3.0f * d);  // the same hit with a longer direction vector
  EXPECT_NEAR(h.distance, 2.0f, 1e-4f);
  EXPECT_NEAR(h.point.z(), 4.0f, 1e-4f);
  EXPECT_FALSE(s.intersect(o, d, 0, 1.9f).hit);
  EXPECT_TRUE(s.occluded(o, d, 0, 2.1f));
  EXPECT_FALSE(s.occluded(o, d, 0, 1.9f));
}

TEST(SyntheticScene, ShadingIsViewIndependentWithoutSpecular) {
  const SyntheticScene& s = scene("room360");
  // A floor point in the corner towards the light: no object can shadow it.
  const Eigen::Vector3f eye(3.0f, 3.0f, 1.5f);
  const SurfaceHit h = s.intersect(eye, {0.0f, 0.0f, -1.0f});
  ASSERT_TRUE(h.hit);
  ASSERT_EQ(s.objectNames()[h.object], "room_floor");
  const Eigen::Vector3f l = vec3(s.manifest["light"]["direction"]);
  // Towards the light the first thing is the room itself (which casts no shadow).
  const SurfaceHit towards_light = s.intersect(h.point + 1e-3f * h.normal, l);
  ASSERT_TRUE(towards_light.hit);
  ASSERT_EQ(s.objectNames()[towards_light.object].rfind("room_", 0), 0u);
  const Eigen::Vector3f a = s.shade(h, eye);
  const Eigen::Vector3f b = s.shade(h, h.point + Eigen::Vector3f(-1.0f, 0.5f, 2.0f));
  EXPECT_EQ(a, b);
  // With the highlight on, looking along the mirrored light direction brightens it;
  // looking from far off the mirror direction does not.
  const Eigen::Vector3f mirror(-l.x(), -l.y(), l.z());
  EXPECT_GT(s.shade(h, h.point + 0.5f * mirror, true).sum(), a.sum() + 0.05f);
  EXPECT_NEAR(s.shade(h, h.point + Eigen::Vector3f(l.x(), l.y(), 0.1f), true).sum(), a.sum(), 1e-3f);
}

// ------------------------------------------------------------------ depth

TEST(SyntheticScene, DepthUnprojectsToTheFirstHit) {
  const SyntheticScene& s = scene("room360");
  for (int v : {0, 17, 90}) {
    const Camera& cam = s.cameras[v];
    const ImageF depth = s.renderDepth(cam);
    ASSERT_EQ(depth.channels, 1);
    ASSERT_EQ(depth.width, cam.K.width);
    for (float z : depth.data) ASSERT_GT(z, 0.0f) << "empty pixel in room360 view " << v;
    std::mt19937_64 rng(v);
    const Eigen::Vector3d c = cam.center();
    for (int k = 0; k < 300; ++k) {
      const int x = static_cast<int>(rng() % cam.K.width), y = static_cast<int>(rng() % cam.K.height);
      const double z = depth.at(x, y);
      const Eigen::Vector3d X = cam.unproject({x + 0.5, y + 0.5}, z);
      const Eigen::Vector3d ray = X - c;
      const SurfaceHit h = s.intersect(c.cast<float>(), ray.normalized().cast<float>());
      ASSERT_TRUE(h.hit);
      EXPECT_NEAR(h.distance, ray.norm(), 1e-4 * ray.norm() + 1e-4) << v << " " << x << "," << y;
    }
  }
}

TEST(SyntheticScene, ObjectLayoutHasBackgroundWithZeroDepth) {
  const SyntheticScene& s = scene("object");
  const Camera& cam = s.cameras[5];
  const ImageF depth = s.renderDepth(cam);
  const ImageF img = s.render(cam);
  int fg = 0, bg = 0;
  for (int y = 0; y < depth.height; ++y)
    for (int x = 0; x < depth.width; ++x) (depth.at(x, y) > 0 ? fg : bg)++;
  EXPECT_GT(fg, depth.width * depth.height / 10);
  EXPECT_GT(bg, depth.width * depth.height / 4);
  // Corners are far outside the object: depth 0 and exactly the background colour.
  for (auto [x, y] :
       {std::pair{0, 0}, {depth.width - 1, 0}, {0, depth.height - 1}, {depth.width - 1, depth.height - 1}}) {
    EXPECT_EQ(depth.at(x, y), 0.0f);
    EXPECT_EQ(pixel(img, x, y), s.background);
  }
  // The centre ray goes through the origin, inside the object: depth below 4 - ~0.5.
  const float zc = depth.at(depth.width / 2, depth.height / 2);
  EXPECT_GT(zc, 2.9f);
  EXPECT_LT(zc, 3.6f);
}

TEST(SyntheticScene, DepthIsConsistentAcrossNearbyViews) {
  const SyntheticScene& s = scene("room360");
  for (auto [ia, ib] : {std::pair{10, 11}, {60, 62}}) {
    const Camera& A = s.cameras[ia];
    const Camera& B = s.cameras[ib];
    const ImageF da = s.renderDepth(A), db = s.renderDepth(B);
    const Eigen::Vector3d cb = B.center();
    int covisible = 0, agree = 0, smooth = 0, smooth_agree = 0;
    for (int y = 0; y < da.height; ++y)
      for (int x = 0; x < da.width; ++x) {
        const Eigen::Vector3d X = A.unproject({x + 0.5, y + 0.5}, da.at(x, y));
        const auto uv = B.project(X);
        if (!uv || !B.inImage(*uv)) continue;
        const Eigen::Vector3d seg = X - cb;
        // Co-visible: nothing blocks the segment from B's centre to just before X.
        const double eps = 2e-3 / seg.norm();
        if (s.occluded(cb.cast<float>(), seg.cast<float>(), 0.0f, static_cast<float>(1 - eps))) continue;
        ++covisible;
        const double zb = B.toCamera(X).z();
        // B's depth at uv: bilinear in 1/z between the four nearest pixel centres (exact
        // on planes, since 1/z is affine in the image there).
        const double fx = std::clamp(uv->x() - 0.5, 0.0, db.width - 1.0);
        const double fy = std::clamp(uv->y() - 0.5, 0.0, db.height - 1.0);
        const int x0 = std::min(static_cast<int>(fx), db.width - 2);
        const int y0 = std::min(static_cast<int>(fy), db.height - 2);
        const double tx = fx - x0, ty = fy - y0;
        auto inv = [&](int xx, int yy) { return 1.0 / db.at(xx, yy); };
        const double inv_z = (1 - ty) * ((1 - tx) * inv(x0, y0) + tx * inv(x0 + 1, y0)) +
                             ty * ((1 - tx) * inv(x0, y0 + 1) + tx * inv(x0 + 1, y0 + 1));
        const bool ok = std::abs(1.0 / inv_z - zb) <= 0.01 * zb;
        agree += ok;
        // Away from depth edges in B (the four neighbours within 5 % of each other)
        // the interpolation is reliable, and nearly all points must agree.
        const float q[4] = {db.at(x0, y0), db.at(x0 + 1, y0), db.at(x0, y0 + 1), db.at(x0 + 1, y0 + 1)};
        if (*std::max_element(q, q + 4) < 1.05f * *std::min_element(q, q + 4)) {
          ++smooth;
          smooth_agree += ok;
        }
      }
    EXPECT_GT(covisible, da.width * da.height / 2) << ia << "->" << ib;
    EXPECT_GT(agree, 0.9 * covisible) << ia << "->" << ib;
    EXPECT_GT(smooth, 0.8 * covisible) << ia << "->" << ib;
    EXPECT_GT(smooth_agree, 0.99 * smooth) << ia << "->" << ib << ": " << smooth_agree << "/" << smooth;
  }
}

// ------------------------------------------------------------------ rendering

TEST(SyntheticScene, RenderIsDeterministicAndThreadCountIndependent) {
  const SyntheticScene& s = scene("room360");
  const Camera& cam = s.cameras[33];
  const ImageF a = s.render(cam);
  const ImageF b = s.render(cam);
  EXPECT_EQ(a.data, b.data);
  ImageF one, two;
  tbb::task_arena(1).execute([&] { one = s.render(cam); });
  tbb::task_arena(2).execute([&] { two = s.render(cam); });
  EXPECT_EQ(one.data, a.data);
  EXPECT_EQ(two.data, a.data);
  // A scene built again from the same options renders the same image.
  const SyntheticScene again = makeSyntheticScene(test::syntheticOptions("room360", 128, 96, /*seed=*/3));
  EXPECT_EQ(again.render(again.cameras[33]).data, a.data);
  EXPECT_EQ(again.manifest, s.manifest);
}

TEST(SyntheticScene, RoomImagesAreFullFiniteAndTextured) {
  const SyntheticScene& s = scene("room360");
  for (int v : {0, 40, 101}) {
    const ImageF img = s.render(s.cameras[v]);
    ASSERT_EQ(img.channels, 3);
    ASSERT_EQ(img.width, 128);
    ASSERT_EQ(img.height, 96);
    double sum = 0, sum2 = 0;
    for (float x : img.data) {
      ASSERT_TRUE(std::isfinite(x));
      ASSERT_GE(x, 0.0f);
      ASSERT_LE(x, 1.0f);
      sum += x;
      sum2 += double(x) * x;
    }
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) ASSERT_NE(pixel(img, x, y), s.background) << x << "," << y;
    const double n = static_cast<double>(img.data.size());
    const double sd = std::sqrt(sum2 / n - (sum / n) * (sum / n));
    EXPECT_GT(sd, 0.1) << "view " << v << " looks flat";
    EXPECT_GT(sum / n, 0.2);
  }
}

TEST(SyntheticScene, SupersamplingReducesAliasing) {
  const SyntheticScene& s = scene("object");
  const Camera& cam = s.cameras[12];
  const ImageF reference = synth::renderGrid(s, cam, 8, true, false);  // 64 spp
  const ImageF centre = synth::renderGrid(s, cam, 1, false, false);    // 1 spp, no AA
  const ImageF four = s.render(cam, {.samples_per_pixel = 4});
  const double e1 = meanAbsDiff(centre, reference), e4 = meanAbsDiff(four, reference);
  EXPECT_LT(e4, 0.75 * e1) << "1 spp: " << e1 << ", 4 spp: " << e4;
  // Fewer than 4 samples are raised to 4.
  EXPECT_EQ(s.render(cam, {.samples_per_pixel = 1}).data, four.data);
  EXPECT_EQ(synth::gridForSamples(1), 2);
  EXPECT_EQ(synth::gridForSamples(9), 3);
  EXPECT_EQ(synth::gridForSamples(10), 4);
}

// ------------------------------------------------------------------ layouts

TEST(SyntheticScene, SurfaceSamplesLieOnSurfaces) {
  const SyntheticScene& s = scene("room360");
  std::mt19937_64 rng(5);
  const auto samples = s.sampleSurface(3000, rng);
  ASSERT_EQ(samples.size(), 3000u);
  const auto names = s.objectNames();
  int on_surface = 0;
  for (const auto& p : samples) {
    ASSERT_GE(p.object, 0);
    ASSERT_LT(p.object, static_cast<int>(names.size()));
    EXPECT_NEAR(p.normal.norm(), 1.0f, 1e-5f);
    // From just outside, back along the normal: the surface is there. (A sample within
    // a few mm of another surface, e.g. where an object rests on the floor, may meet
    // that one first, so a few are allowed to land elsewhere within the window.)
    const float eps = 2e-3f;
    const SurfaceHit h = s.intersect(p.point + eps * p.normal, -p.normal, 0.0f, 2 * eps);
    ASSERT_TRUE(h.hit) << names[p.object];
    on_surface += (h.point - p.point).norm() < 1e-3f;
  }
  EXPECT_GE(on_surface, 0.995 * samples.size());
  std::mt19937_64 r1(9), r2(9);
  const auto a = s.sampleSurface(100, r1), b = s.sampleSurface(100, r2);
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].point, b[i].point);
}

TEST(SyntheticScene, SurfaceSampleCountsFollowArea) {
  const SyntheticScene& s = scene("room360");
  const Eigen::Vector3f lo = vec3(s.manifest["room"]["min"]), hi = vec3(s.manifest["room"]["max"]);
  const Eigen::Vector3f e = hi - lo;
  const auto names = s.objectNames();
  std::map<std::string, int> count;
  std::mt19937_64 rng(21);
  const std::size_t N = 200000;
  for (const auto& p : s.sampleSurface(N, rng)) {
    ++count[names[p.object]];
    if (names[p.object] == "room_floor") {
      EXPECT_NEAR(p.point.z(), lo.z(), 1e-4f);
      EXPECT_GT(p.normal.z(), 0.999f);  // the room's faces point inward
    }
  }
  const double floor_area = e.x() * e.y(), wall_x_area = e.y() * e.z(), wall_y_area = e.x() * e.z();
  // Ratios among the room's faces; relative sampling noise is about 1/sqrt(count) ~ 1 %.
  EXPECT_NEAR(double(count["room_ceiling"]) / count["room_floor"], 1.0, 0.04);
  EXPECT_NEAR(double(count["room_wall_xlo"]) / count["room_floor"], wall_x_area / floor_area, 0.03);
  EXPECT_NEAR(double(count["room_wall_yhi"]) / count["room_floor"], wall_y_area / floor_area, 0.03);
  // The crate is a cube: its area is 6 side^2, with the side from its bounding box.
  for (const auto& o : s.manifest["objects"])
    if (o["name"] == "crate") {
      // Its box is turned about z, so the side comes from the height.
      const double side = o["bbox_max"][2].get<double>() - o["bbox_min"][2].get<double>();
      EXPECT_NEAR(double(count["crate"]) / count["room_floor"], 6 * side * side / floor_area,
                  0.1 * 6 * side * side / floor_area);
    }
}

// ------------------------------------------------------------------ files

namespace {

// An octahedron stretched along y (its up axis): 6 vertices, 8 faces, outward.
std::string writeTallOctahedron() {
  const std::string path = tempPath("tall_octahedron.off");
  std::ofstream f(path);
  f << "OFF\n6 8 0\n"
    << "0.5 0 0\n-0.5 0 0\n0 2 0\n0 -2 0\n0 0 0.5\n0 0 -0.5\n"
    << "3 0 2 4\n3 2 1 4\n3 1 3 4\n3 3 0 4\n3 2 0 5\n3 1 2 5\n3 3 1 5\n3 0 3 5\n";
  return path;
}

}  // namespace

TEST(SyntheticFiles, MeshFileBecomesTheObjectWithItsUpAxis) {
  SyntheticOptions o;
  o.layout = "object";
  o.width = 96;
  o.height = 72;
  o.meshes = {writeTallOctahedron()};
  o.up_axis = "y";
  const SyntheticScene s = makeSyntheticScene(o);
  ASSERT_EQ(s.manifest["objects"].size(), 1u);
  const auto& obj = s.manifest["objects"][0];
  EXPECT_EQ(obj["mesh"], o.meshes[0]);
  const Eigen::Vector3f lo = vec3(obj["bbox_min"]), hi = vec3(obj["bbox_max"]);
  // Normalised to radius 1 about the origin, with the long (up) axis now along z.
  EXPECT_NEAR(hi.z(), 1.0f, 1e-5f);
  EXPECT_NEAR(lo.z(), -1.0f, 1e-5f);
  EXPECT_NEAR(hi.x(), 0.25f, 1e-5f);
  EXPECT_NEAR(hi.y(), 0.25f, 1e-5f);
  // A camera looking at the origin sees it.
  const ImageF depth = s.renderDepth(s.cameras[0]);
  EXPECT_GT(depth.at(depth.width / 2, depth.height / 2), 0.0f);
  EXPECT_EQ(s.cameras.size(), 150u);
  // The same file with up axis z stays lying down.
  o.up_axis = "z";
  const SyntheticScene lying = makeSyntheticScene(o);
  EXPECT_NEAR(vec3(lying.manifest["objects"][0]["bbox_max"]).y(), 1.0f, 1e-5f);
}

TEST(SyntheticFiles, MeshFileCyclesThroughRoomObjects) {
  // A real scanned mesh: the Stanford bunny from libcgal-demo (install_deps.sh).
  ::setenv("SARESGS_DATA_CACHE", tempPath("cgal").c_str(), 1);
  const std::string mesh = resolveAsset("cgal:bunny00");
  ::unsetenv("SARESGS_DATA_CACHE");
  SyntheticOptions o;
  o.layout = "room360";
  o.width = 64;
  o.height = 48;
  o.meshes = {mesh};
  const SyntheticScene s = makeSyntheticScene(o);
  int from_file = 0;
  for (const auto& obj : s.manifest["objects"]) from_file += obj["mesh"] == mesh;
  EXPECT_EQ(from_file, 6);  // every content object cycles through the one file
  const ImageF img = s.render(s.cameras[3]);
  for (float x : img.data) ASSERT_TRUE(std::isfinite(x));
}

TEST(SyntheticFiles, PhotographTexturesColourTheObjects) {
  // A photograph without blue: every fully covered object pixel then has no blue.
  Image8 photo(32, 16, 3, 0);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 32; ++x) {
      photo.at(x, y, 0) = static_cast<std::uint8_t>(x * 8);
      photo.at(x, y, 1) = static_cast<std::uint8_t>(255 - y * 16);
    }
  const std::string path = tempPath("no_blue.png");
  writeImage(path, photo);
  for (const char* projection : {"triplanar", "spherical"}) {
    SyntheticOptions o;
    o.layout = "object";
    o.width = 96;
    o.height = 72;
    o.textures = {path};
    o.projection = projection;
    const SyntheticScene s = makeSyntheticScene(o);
    const Camera& cam = s.cameras[2];
    const ImageF img = s.render(cam);
    const ImageF depth = s.renderDepth(cam);
    int inner = 0;
    double green = 0;
    for (int y = 1; y + 1 < img.height; ++y)
      for (int x = 1; x + 1 < img.width; ++x) {
        bool covered = true;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) covered = covered && depth.at(x + dx, y + dy) > 0;
        if (!covered) continue;
        ++inner;
        EXPECT_EQ(img.at(x, y, 2), 0.0f) << projection << " " << x << "," << y;
        green += img.at(x, y, 1);
      }
    EXPECT_GT(inner, 200) << projection;
    EXPECT_GT(green / inner, 0.1) << projection;
    for (const auto& obj : s.manifest["objects"]) EXPECT_EQ(obj["texture"], path);
  }
}

TEST(SyntheticFiles, BadOptionsThrowInputErrorsNamingThem) {
  SyntheticOptions o;
  o.width = 32;
  o.height = 24;
  auto message = [&](const SyntheticOptions& opts) -> std::string {
    try {
      makeSyntheticScene(opts);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  SyntheticOptions bad = o;
  bad.layout = "kitchen";
  EXPECT_NE(message(bad).find("kitchen"), std::string::npos);
  EXPECT_NE(message(bad).find("layout"), std::string::npos);
  bad = o;
  bad.meshes = {tempPath("no_such_mesh.off")};
  EXPECT_NE(message(bad).find("no_such_mesh.off"), std::string::npos);
  bad = o;
  bad.textures = {tempPath("no_such_photo.png")};
  EXPECT_NE(message(bad).find("no_such_photo.png"), std::string::npos);
  bad = o;
  bad.meshes = {writeTallOctahedron()};
  bad.up_axis = "up";
  EXPECT_NE(message(bad).find("up_axis"), std::string::npos);
  bad = o;
  bad.projection = "cubic";
  EXPECT_NE(message(bad).find("projection"), std::string::npos);
  bad = o;
  bad.width = 0;
  EXPECT_NE(message(bad).find("width"), std::string::npos);
}
