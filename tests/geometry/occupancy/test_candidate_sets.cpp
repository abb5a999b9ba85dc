// Candidate voxel sets: frustum set vs brute force over all voxels, Embree visible set vs
// an independent voxel DDA (Amanatides-Woo) in double precision.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include <set>
#include <unordered_set>

#include "common/test_support.h"
#include "geometry/occupancy/candidate_sets.h"
#include "occupancy_test_support.h"

using namespace saresgs;

namespace {

Intrinsics candidateK(int w = 96, int h = 72) {
  return Intrinsics{.width = w, .height = h, .fx = 0.9 * w, .fy = 0.9 * w, .cx = 0.5 * w + 1.25, .cy = 0.5 * h - 0.75};
}

// A scene grid whose coarse voxels are a random subset of a 24 x 18 x 12 box (each chosen
// voxel gets m = 1 point at a random place inside it; two frame points fix the box).
OccupancyGrids randomGrid(std::mt19937_64& rng, double density, int upsample) {
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Eigen::Vector3d> pts{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(24, 18, 12)};
  for (int x = 0; x < 24; ++x)
    for (int y = 0; y < 18; ++y)
      for (int z = 0; z < 12; ++z)
        if (u(rng) < density) pts.emplace_back(x + 0.1 + 0.8 * u(rng), y + 0.1 + 0.8 * u(rng), z + 0.1 + 0.8 * u(rng));
  OccupancyOptions o;
  o.resolution = 24;
  o.min_points = 1;
  o.upsample = upsample;
  return OccupancyGrids::fromSfm(pts, o);
}

// Cameras looking at the box from outside, from inside, and in random directions.
std::vector<Camera> probeCameras(std::mt19937_64& rng, const AABB& box, int count) {
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> n(0, 1);
  std::vector<Camera> cams;
  const Eigen::Vector3d c = box.center();
  const double r = box.size().norm();
  for (int i = 0; i < count; ++i) {
    Eigen::Vector3d dir(n(rng), n(rng), n(rng));
    dir.normalize();
    Eigen::Vector3d eye, target;
    switch (i % 3) {
      case 0:
        eye = c + (0.7 + 0.6 * u(rng)) * r * dir;
        target = c;
        break;  // outside
      case 1:   // inside the box, looking somewhere
        eye = box.min + Eigen::Vector3d(u(rng), u(rng), u(rng)).cwiseProduct(box.size());
        target = eye + Eigen::Vector3d(n(rng), n(rng), n(rng));
        break;
      default:
        eye = c + 0.4 * r * dir;
        target = c + 0.2 * r * Eigen::Vector3d(n(rng), n(rng), n(rng));
        break;
    }
    cams.push_back(Camera::lookAt(candidateK(), eye, target, Eigen::Vector3d(n(rng), n(rng), n(rng))));
  }
  return cams;
}

// Brute force: every scene voxel's centre through Camera::project.
std::set<Voxel> bruteFrustum(const OccupancyGrids& g, const Camera& cam, const DepthRange& r) {
  std::set<Voxel> out;
  for (const Voxel& v : g.sceneVoxels().voxels()) {
    const Eigen::Vector3d x = g.voxelCenter(v);
    const double z = cam.toCamera(x).z();
    if (!(z >= r.near && z <= r.far)) continue;
    const auto uv = cam.project(x);
    if (uv && uv->x() >= 0 && uv->y() >= 0 && uv->x() <= cam.K.width && uv->y() <= cam.K.height) out.insert(v);
  }
  return out;
}

// Independent first-hit oracle: 3D DDA over a hash set of occupied voxels, in voxel
// units, double precision. Returns the first occupied voxel the ray enters (the one that
// contains the origin if occupied).
class DdaOracle {
 public:
  explicit DdaOracle(const OccupancyGrids& g) : g_(g) {
    for (const Voxel& v : g.sceneVoxels().voxels()) {
      occ_.insert(packVoxel(v));
      for (int a = 0; a < 3; ++a) {
        lo_[a] = std::min(lo_[a], v[a]);
        hi_[a] = std::max(hi_[a], v[a]);
      }
    }
  }

  std::optional<Voxel> firstHit(const Eigen::Vector3d& origin_w, const Eigen::Vector3d& dir_w) const {
    if (occ_.empty()) return std::nullopt;
    const Eigen::Vector3d o = (origin_w - g_.origin()) / g_.voxelSize();
    const Eigen::Vector3d d = dir_w.normalized();
    // Clip to the box of occupied voxels [lo, hi + 1].
    double t0 = 0, t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      const double blo = lo_[a], bhi = hi_[a] + 1.0;
      if (d[a] == 0) {
        if (o[a] < blo || o[a] > bhi) return std::nullopt;
        continue;
      }
      double ta = (blo - o[a]) / d[a], tb = (bhi - o[a]) / d[a];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    if (t0 > t1) return std::nullopt;
    const Eigen::Vector3d p = o + t0 * d;
    Voxel v;
    int step[3];
    double tmax[3], tdelta[3];
    for (int a = 0; a < 3; ++a) {
      v[a] = std::clamp(static_cast<int>(std::floor(p[a])), lo_[a], hi_[a]);
      step[a] = d[a] > 0 ? 1 : (d[a] < 0 ? -1 : 0);
      if (step[a] == 0) {
        tmax[a] = tdelta[a] = std::numeric_limits<double>::infinity();
      } else {
        const double boundary = v[a] + (step[a] > 0 ? 1.0 : 0.0);
        tmax[a] = (boundary - o[a]) / d[a];
        tdelta[a] = 1.0 / std::abs(d[a]);
      }
    }
    for (;;) {
      if (occ_.count(packVoxel(v))) return v;
      int a = 0;
      if (tmax[1] < tmax[a]) a = 1;
      if (tmax[2] < tmax[a]) a = 2;
      v[a] += step[a];
      if (v[a] < lo_[a] || v[a] > hi_[a]) return std::nullopt;
      tmax[a] += tdelta[a];
    }
  }

 private:
  const OccupancyGrids& g_;
  std::unordered_set<VoxelKey> occ_;
  Voxel lo_{INT32_MAX, INT32_MAX, INT32_MAX}, hi_{INT32_MIN, INT32_MIN, INT32_MIN};
};

struct Agreement {
  std::size_t rays = 0, agree = 0, hits = 0;
  double rate() const { return rays ? static_cast<double>(agree) / rays : 1.0; }
};

void compareWithOracle(const OccupancyGrids& g, const VisibilityTracer& tracer, const Camera& cam, int stride,
                       Agreement& acc) {
  const DdaOracle oracle(g);
  const auto uv = samplePixels(cam.K, stride);
  const auto hits = tracer.tracePixels(cam, stride);
  ASSERT_EQ(hits.size(), uv.size());
  const auto& keys = g.sceneVoxels().keys();
  for (std::size_t i = 0; i < uv.size(); ++i) {
    const auto want = oracle.firstHit(cam.center(), cam.rayDirection(uv[i]));
    const std::optional<Voxel> got = hits[i] >= 0 ? std::optional<Voxel>(unpackVoxel(keys[hits[i]])) : std::nullopt;
    ++acc.rays;
    acc.agree += (want == got);
    acc.hits += got.has_value();
  }
}

}  // namespace

TEST(FrustumSet, EqualsBruteForceOverAllVoxels) {
  std::mt19937_64 rng(11);
  std::size_t total = 0, nonempty = 0;
  for (double density : {0.02, 0.2, 0.7}) {
    const OccupancyGrids g = randomGrid(rng, density, 2);
    ASSERT_GT(g.sceneCount(), 0u);
    for (const Camera& cam : probeCameras(rng, g.box(), 30)) {
      const DepthRange r = sceneDepthRange(g, cam);
      const std::set<Voxel> expect = bruteFrustum(g, cam, r);
      const auto got = frustumSet(g, cam).voxels();
      EXPECT_EQ(std::set<Voxel>(got.begin(), got.end()), expect);
      // A near/far slab through the middle of the scene exercises both depth planes.
      if (!r.empty()) {
        const DepthRange mid{r.near + 0.3 * (r.far - r.near), r.near + 0.6 * (r.far - r.near)};
        const auto got_mid = frustumSet(g, cam, mid).voxels();
        EXPECT_EQ(std::set<Voxel>(got_mid.begin(), got_mid.end()), bruteFrustum(g, cam, mid));
      }
      total += expect.size();
      nonempty += !expect.empty();
    }
  }
  // Not vacuous: most cameras see voxels, and not all of them.
  EXPECT_GT(nonempty, 60u);
  EXPECT_GT(total, 10000u);
}

TEST(FrustumSet, SceneDepthRangeCoversTheVoxelBox) {
  std::mt19937_64 rng(12);
  const OccupancyGrids g = randomGrid(rng, 0.3, 1);
  const Camera outside = Camera::lookAt(candidateK(), Eigen::Vector3d(12, -40, 6), g.box().center());
  const DepthRange r = sceneDepthRange(g, outside);
  ASSERT_FALSE(r.empty());
  for (const Voxel& v : g.sceneVoxels().voxels()) {
    const double z = outside.toCamera(g.voxelCenter(v)).z();
    EXPECT_GE(z, r.near);
    EXPECT_LE(z, r.far);
  }
  // Inside the box: near is clamped to a positive depth, far stays finite.
  const Camera inside = Camera::lookAt(candidateK(), g.box().center(), Eigen::Vector3d(0, 0, 0));
  const DepthRange ri = sceneDepthRange(g, inside);
  EXPECT_GT(ri.near, 0.0);
  EXPECT_TRUE(std::isfinite(ri.far));
  EXPECT_GT(ri.far, ri.near);
}

TEST(VisibleSet, EmbreeAgreesWithDdaOracleOnRandomGrids) {
  std::mt19937_64 rng(13);
  Agreement all;
  for (double density : {0.01, 0.1, 0.5})
    for (int upsample : {1, 2}) {
      const OccupancyGrids g = randomGrid(rng, density, upsample);
      const VisibilityTracer tracer(g);
      ASSERT_EQ(tracer.voxelCount(), g.sceneCount());
      Agreement a;
      for (const Camera& cam : probeCameras(rng, g.box(), 12)) compareWithOracle(g, tracer, cam, 2, a);
      EXPECT_GE(a.rate(), 0.999) << "density " << density << " upsample " << upsample;
      EXPECT_GT(a.hits, a.rays / 10);  // the rays do hit voxels
      all.rays += a.rays;
      all.agree += a.agree;
      all.hits += a.hits;
    }
  std::printf("[ visible vs DDA, random grids ] %zu rays, %zu hits, agreement %.5f %%\n", all.rays, all.hits,
              100.0 * all.rate());
  EXPECT_GE(all.rate(), 0.999);
}

TEST(VisibleSet, EmbreeAgreesWithDdaOracleOnRoom360) {
  const auto& s = test::room360Sfm();
  OccupancyOptions o;
  o.resolution = 64;
  o.min_points = 2;
  o.upsample = 2;
  const OccupancyGrids g = OccupancyGrids::fromSfm(s.points, o);
  ASSERT_GT(g.sceneCount(), 1000u);
  const VisibilityTracer tracer(g);
  Agreement a;
  for (std::size_t i = 0; i < s.scene.cameras.size(); i += 5) compareWithOracle(g, tracer, s.scene.cameras[i], 2, a);
  std::printf("[ visible vs DDA, room360 ] %zu rays, %zu hits, agreement %.5f %%\n", a.rays, a.hits, 100.0 * a.rate());
  EXPECT_GE(a.rate(), 0.999);
  // Sparse SfM leaves holes in the walls (most wall voxels hold fewer than m points), so
  // many rays leave the room; enough hit for the agreement to mean something.
  EXPECT_GT(a.hits, a.rays / 5);
}

TEST(VisibleSet, SetIsTheUnionOfRayHitsAndHidesOccludedVoxels) {
  // Two walls of voxels along y: a camera in front sees only the near wall.
  std::vector<Eigen::Vector3d> pts{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(16, 16, 16)};
  for (int x = 0; x < 16; ++x)
    for (int z = 0; z < 16; ++z) {
      pts.emplace_back(x + 0.5, 4.5, z + 0.5);
      pts.emplace_back(x + 0.5, 12.5, z + 0.5);
    }
  OccupancyOptions o;
  o.resolution = 16;
  o.min_points = 1;
  o.upsample = 1;
  const OccupancyGrids g = OccupancyGrids::fromSfm(pts, o);
  ASSERT_EQ(g.sceneCount(), 2u * 256 + 2);  // the frame points occupy two more voxels
  const Camera cam = Camera::lookAt(candidateK(), Eigen::Vector3d(8, -20, 8), Eigen::Vector3d(8, 8, 8));
  const VisibilityTracer tracer(g);
  const VoxelSet vis = tracer.visibleSet(cam, 1);
  const VoxelSet fr = frustumSet(g, cam);
  std::size_t near_wall = 0;
  for (const Voxel& v : vis.voxels()) {
    EXPECT_NE(v[1], 12) << "a voxel of the hidden wall counted as visible";
    near_wall += v[1] == 4;
  }
  EXPECT_GT(near_wall, 100u);
  std::size_t far_in_frustum = 0;
  for (const Voxel& v : fr.voxels()) far_in_frustum += v[1] == 12;
  EXPECT_GT(far_in_frustum, 100u);  // the frustum set ignores occlusion (the paper's)
  // visibleSet is exactly the set of hit voxels of tracePixels.
  std::set<VoxelKey> hit;
  for (auto h : tracer.tracePixels(cam, 1))
    if (h >= 0) hit.insert(g.sceneVoxels().keys()[h]);
  EXPECT_EQ(std::vector<VoxelKey>(hit.begin(), hit.end()), vis.keys());
  // Stride 4 samples a subset of the rays.
  EXPECT_LE(tracer.visibleSet(cam, 4).size(), vis.size());
}

TEST(CandidateSets, SamplePixels) {
  const Intrinsics K = candidateK(10, 7);
  const auto all = samplePixels(K, 1);
  ASSERT_EQ(all.size(), 70u);
  EXPECT_EQ(all.front(), Eigen::Vector2d(0.5, 0.5));
  EXPECT_EQ(all.back(), Eigen::Vector2d(9.5, 6.5));
  const auto s4 = samplePixels(K, 4);
  ASSERT_EQ(s4.size(), 3u * 2u);  // blocks [0,4) [4,8) [8,10) x [0,4) [4,7)
  EXPECT_EQ(s4[0], Eigen::Vector2d(2, 2));
  EXPECT_EQ(s4[2], Eigen::Vector2d(9, 2));
  EXPECT_EQ(s4[5], Eigen::Vector2d(9, 5.5));
  EXPECT_TRUE(test::throwsInputError([&] { samplePixels(K, 0); }, "candidate camera", "pixel_stride"));
}

TEST(CandidateSets, CameraThatSeesNothingAndDegenerateCameras) {
  std::mt19937_64 rng(14);
  const OccupancyGrids g = randomGrid(rng, 0.2, 2);
  const VisibilityTracer tracer(g);
  // Looking away from the box.
  const Camera away = Camera::lookAt(candidateK(), Eigen::Vector3d(12, -30, 6), Eigen::Vector3d(12, -60, 6));
  EXPECT_TRUE(sceneDepthRange(g, away).empty());
  EXPECT_TRUE(frustumSet(g, away).empty());
  EXPECT_TRUE(tracer.visibleSet(away, 1).empty());

  Camera bad = away;
  bad.K.fx = 0;
  EXPECT_TRUE(test::throwsInputError([&] { frustumSet(g, bad); }, "candidate camera", "K/R/t"));
  EXPECT_TRUE(test::throwsInputError([&] { tracer.visibleSet(bad); }, "candidate camera", "K/R/t"));
  bad = away;
  bad.K.width = 0;
  EXPECT_TRUE(test::throwsInputError([&] { frustumSet(g, bad); }, "candidate camera", "K/R/t"));
  bad = away;
  bad.t.x() = NAN;
  EXPECT_TRUE(test::throwsInputError([&] { tracer.visibleSet(bad); }, "candidate camera", "K/R/t"));
  bad = away;
  bad.R(0, 0) = 2;
  EXPECT_TRUE(test::throwsInputError([&] { sceneDepthRange(g, bad); }, "candidate camera", "K/R/t"));
  EXPECT_TRUE(test::throwsInputError([&] { frustumSet(g, away, DepthRange{NAN, 1}); }, "candidate camera", "near/far"));
  // A 1x1 image and a camera inside a voxel work.
  const Camera tiny = Camera::lookAt(candidateK(1, 1), Eigen::Vector3d(12, -30, 6), g.box().center());
  EXPECT_LE(tracer.visibleSet(tiny, 4).size(), 1u);
  const Voxel v0 = g.sceneVoxels().voxels().front();
  const Camera in_voxel = Camera::lookAt(candidateK(), g.voxelCenter(v0), g.box().center());
  const auto hits = tracer.tracePixels(in_voxel, 8);
  for (auto h : hits) EXPECT_EQ(h, 0) << "a ray from inside voxel 0 hits it first";
  // Rays with zero or non-finite direction miss.
  EXPECT_EQ(tracer.firstHit(g.box().center(), Eigen::Vector3d::Zero()), -1);
  EXPECT_EQ(tracer.firstHit(g.box().center(), Eigen::Vector3d(NAN, 0, 1)), -1);
}

TEST(CandidateSets, EmptySceneGrid) {
  OccupancyOptions o;
  o.resolution = 10;
  const OccupancyGrids g =
      OccupancyGrids::fromSfm(std::vector<Eigen::Vector3d>{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(10, 10, 10)}, o);
  ASSERT_EQ(g.sceneCount(), 0u);
  const Camera cam = Camera::lookAt(candidateK(), Eigen::Vector3d(5, -20, 5), Eigen::Vector3d(5, 5, 5));
  EXPECT_TRUE(sceneDepthRange(g, cam).empty());
  EXPECT_TRUE(frustumSet(g, cam).empty());
  const VisibilityTracer tracer(g);
  EXPECT_EQ(tracer.voxelCount(), 0u);
  EXPECT_TRUE(tracer.visibleSet(cam, 1).empty());
  for (auto h : tracer.tracePixels(cam, 8)) EXPECT_EQ(h, -1);
}

TEST(CandidateSets, DeterministicAcrossRuns) {
  const auto& s = test::room360Sfm();
  OccupancyOptions o;
  o.resolution = 64;
  const OccupancyGrids g = OccupancyGrids::fromSfm(s.points, o);
  const VisibilityTracer t1(g), t2(g);
  for (std::size_t i = 0; i < s.scene.cameras.size(); i += 17) {
    const Camera& c = s.scene.cameras[i];
    EXPECT_EQ(t1.tracePixels(c, 2), t2.tracePixels(c, 2));
    EXPECT_EQ(frustumSet(g, c), frustumSet(g, c));
  }
}
