// Scene and observed grids: thresholds, upsampling, trimming, dilation vs brute force.
#include <gtest/gtest.h>
#include <link.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "common/test_support.h"
#include "geometry/occupancy/occupancy_grid.h"

using namespace saresgs;

namespace {

// Brute-force dilation: every voxel plus every offset of the radius-r neighbourhood,
// the neighbourhood written from its metric definition (not from OpenVDB's stencils).
std::set<Voxel> bruteDilate(const std::set<Voxel>& in, int r, DilationShape shape) {
  std::vector<Voxel> offsets;
  for (int dx = -r; dx <= r; ++dx)
    for (int dy = -r; dy <= r; ++dy)
      for (int dz = -r; dz <= r; ++dz) {
        const int l1 = std::abs(dx) + std::abs(dy) + std::abs(dz);
        bool ok = true;  // Cube: the max norm <= r already holds
        if (shape == DilationShape::Octahedron) ok = l1 <= r;
        if (shape == DilationShape::FaceEdge) ok = l1 <= 2 * r;
        if (ok) offsets.push_back({dx, dy, dz});
      }
  std::set<Voxel> out;
  for (const Voxel& v : in)
    for (const Voxel& d : offsets) out.insert({v[0] + d[0], v[1] + d[1], v[2] + d[2]});
  return out;
}

std::set<Voxel> asSet(const VoxelSet& s) {
  const auto v = s.voxels();
  return {v.begin(), v.end()};
}

// Random voxels in a box [-L/2, L/2)^3 (negative coordinates and several 8^3 blocks).
std::set<Voxel> randomVoxels(std::mt19937_64& rng, int L, double density) {
  std::set<Voxel> s;
  std::uniform_real_distribution<double> u(0, 1);
  for (int x = -L / 2; x < L / 2; ++x)
    for (int y = -L / 2; y < L / 2; ++y)
      for (int z = -L / 2; z < L / 2; ++z)
        if (u(rng) < density) s.insert({x, y, z});
  return s;
}

// Two points at the box corners fix a box [0, 10]^3; with resolution 10 the coarse
// voxels are unit cubes.
std::vector<Eigen::Vector3d> unitBoxFrame() { return {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(10, 10, 10)}; }

}  // namespace

TEST(VoxelKey, PackUnpackRoundTripAndBlockOrder) {
  std::mt19937_64 rng(1);
  std::uniform_int_distribution<int> c(-kVoxelCoordLimit, kVoxelCoordLimit - 1);
  for (int i = 0; i < 10000; ++i) {
    const Voxel v{c(rng), c(rng), c(rng)};
    ASSERT_EQ(unpackVoxel(packVoxel(v)), v);
  }
  for (const Voxel& v :
       {Voxel{-kVoxelCoordLimit, -kVoxelCoordLimit, -kVoxelCoordLimit},
        Voxel{kVoxelCoordLimit - 1, kVoxelCoordLimit - 1, kVoxelCoordLimit - 1}, Voxel{-1, 0, 7}, Voxel{-8, -9, 8}})
    EXPECT_EQ(unpackVoxel(packVoxel(v)), v);
  // Keys of one 8^3 block (floor division, negative too) share blockOfKey.
  EXPECT_EQ(blockOfKey(packVoxel({-8, 0, 0})), blockOfKey(packVoxel({-1, 7, 7})));
  EXPECT_NE(blockOfKey(packVoxel({-1, 0, 0})), blockOfKey(packVoxel({0, 0, 0})));
  EXPECT_FALSE(voxelRepresentable({kVoxelCoordLimit, 0, 0}));
  EXPECT_TRUE(test::throwsInputError(
      [] {
        VoxelSet::fromVoxels(std::vector<Voxel>{{kVoxelCoordLimit, 0, 0}});
      },
      "voxel set", "voxel 0"));
}

TEST(VoxelSet, SetOperationsMatchStdSet) {
  std::mt19937_64 rng(2);
  for (double density : {0.0, 0.02, 0.3}) {
    const auto a = randomVoxels(rng, 20, density), b = randomVoxels(rng, 20, density);
    const VoxelSet A = VoxelSet::fromVoxels(std::vector<Voxel>(a.begin(), a.end()));
    const VoxelSet B = VoxelSet::fromVoxels(std::vector<Voxel>(b.begin(), b.end()));
    std::set<Voxel> u, i, d;
    std::set_union(a.begin(), a.end(), b.begin(), b.end(), std::inserter(u, u.end()));
    std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::inserter(i, i.end()));
    std::set_difference(a.begin(), a.end(), b.begin(), b.end(), std::inserter(d, d.end()));
    EXPECT_EQ(asSet(setUnion(A, B)), u);
    EXPECT_EQ(asSet(setIntersection(A, B)), i);
    EXPECT_EQ(asSet(setDifference(A, B)), d);
    EXPECT_EQ(intersectionSize(A, B), i.size());
    EXPECT_EQ(differenceSize(A, B), d.size());
    EXPECT_EQ(symmetricDifferenceSize(A, B), u.size() - i.size());
    for (const Voxel& v : a) EXPECT_TRUE(A.contains(v));
  }
}

TEST(Dilation, OpenVdbEqualsBruteForceOnRandomSparseGrids) {
  std::mt19937_64 rng(3);
  int cases = 0;
  for (double density : {0.0, 0.0005, 0.005, 0.05, 0.3}) {
    // Dense cases in a smaller box keep the brute force (std::set inserts) fast.
    const std::set<Voxel> in = randomVoxels(rng, density < 0.01 ? 40 : 24, density);
    const VoxelSet vin = VoxelSet::fromVoxels(std::vector<Voxel>(in.begin(), in.end()));
    for (DilationShape shape : {DilationShape::Cube, DilationShape::FaceEdge, DilationShape::Octahedron})
      for (int r : {0, 1, 2, 3}) {
        const std::set<Voxel> expect = bruteDilate(in, r, shape);
        const VoxelSet got = dilateVoxels(vin, r, shape);
        EXPECT_EQ(asSet(got), expect) << "density " << density << " radius " << r << " shape "
                                      << static_cast<int>(shape);
        if (density > 0 && r > 0) {
          EXPECT_GT(got.size(), vin.size());  // the check is not vacuous
        }
        ++cases;
      }
  }
  EXPECT_EQ(cases, 60);
  // A single voxel: the kernels themselves, (2r+1)^3 for the cube.
  const VoxelSet one = VoxelSet::fromVoxels(std::vector<Voxel>{{5, -3, 9}});
  EXPECT_EQ(dilateVoxels(one, 2, DilationShape::Cube).size(), 125u);
  EXPECT_EQ(dilateVoxels(one, 2, DilationShape::Octahedron).size(), 25u);
  // 125 minus |d|_1 = 5 (24 offsets like (2,2,1)) and |d|_1 = 6 (8 corners).
  EXPECT_EQ(dilateVoxels(one, 2, DilationShape::FaceEdge).size(), 93u);
  EXPECT_TRUE(test::throwsInputError([&] { dilateVoxels(one, -1); }, "dilation", "radius"));
}

TEST(OccupancyGrids, ThresholdMAndUpsamplingN) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> inside(0.05, 0.95);
  for (int m : {2, 5})
    for (int n : {1, 2, 3}) {
      std::vector<Eigen::Vector3d> pts = unitBoxFrame();
      // m - 1 points in coarse voxel (3,4,5), m in (6,2,1), m + 3 in (0,9,9) (on the box
      // edge), one point in each of 8 others; the frame points add one to (0,0,0) and
      // (9,9,9) (the max corner belongs to the last voxel).
      auto fill = [&](Eigen::Vector3i c, int k) {
        for (int i = 0; i < k; ++i) pts.emplace_back(c.x() + inside(rng), c.y() + inside(rng), c.z() + inside(rng));
      };
      fill({3, 4, 5}, m - 1);
      fill({6, 2, 1}, m);
      fill({0, 9, 9}, m + 3);
      for (int i = 0; i < 8; ++i) fill({i, 7, 2}, 1);
      OccupancyOptions o;
      o.resolution = 10;
      o.min_points = m;
      o.upsample = n;
      const OccupancyGrids g = OccupancyGrids::fromSfm(pts, o);
      EXPECT_NEAR(g.coarseVoxelSize(), 1.0, 1e-12);
      EXPECT_NEAR(g.voxelSize(), 1.0 / n, 1e-12);
      EXPECT_EQ(g.coarseCount(), 2u) << "m=" << m;
      EXPECT_EQ(g.sceneCount(), 2u * n * n * n);
      // Exactly the N^3 fine voxels of the two occupied coarse voxels.
      std::set<Voxel> expect;
      for (Eigen::Vector3i c : {Eigen::Vector3i(6, 2, 1), Eigen::Vector3i(0, 9, 9)})
        for (int dx = 0; dx < n; ++dx)
          for (int dy = 0; dy < n; ++dy)
            for (int dz = 0; dz < n; ++dz) expect.insert({c.x() * n + dx, c.y() * n + dy, c.z() * n + dz});
      EXPECT_EQ(asSet(g.sceneVoxels()), expect);
      for (const Voxel& v : expect) {
        EXPECT_TRUE(g.isSceneOccupied(v));
        // The fine voxel centre lies inside its coarse voxel's world box.
        const Eigen::Vector3d c = g.voxelCenter(v);
        EXPECT_EQ(g.voxelOf(c), v);
      }
      EXPECT_FALSE(g.isSceneOccupied({3 * n, 4 * n, 5 * n}));
    }
}

TEST(OccupancyGrids, RandomPointsMatchABruteForceCount) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> nd(0, 1);
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < 20000; ++i) pts.emplace_back(3 * nd(rng), nd(rng), 0.5 * nd(rng) + 2);
  OccupancyOptions o;
  o.resolution = 48;
  o.min_points = 3;
  o.upsample = 2;
  const OccupancyGrids g = OccupancyGrids::fromSfm(pts, o);
  // Independent count: box, coarse size and clamping recomputed here.
  Eigen::Vector3d lo = pts[0], hi = pts[0];
  for (const auto& p : pts) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double hc = (hi - lo).maxCoeff() / 48;
  std::map<Voxel, int> count;
  for (const auto& p : pts) {
    Voxel c;
    for (int a = 0; a < 3; ++a) {
      const int dim = std::max(1, static_cast<int>(std::ceil((hi[a] - lo[a]) / hc)));
      c[a] = std::clamp(static_cast<int>(std::floor((p[a] - lo[a]) / hc)), 0, dim - 1);
    }
    ++count[c];
  }
  std::set<Voxel> expect;
  std::size_t coarse = 0;
  for (const auto& [c, k] : count)
    if (k >= 3) {
      ++coarse;
      for (int d = 0; d < 8; ++d) expect.insert({2 * c[0] + (d & 1), 2 * c[1] + ((d >> 1) & 1), 2 * c[2] + (d >> 2)});
    }
  ASSERT_GT(coarse, 100u);
  EXPECT_EQ(g.coarseCount(), coarse);
  EXPECT_EQ(asSet(g.sceneVoxels()), expect);
  EXPECT_NEAR((g.origin() - lo).norm(), 0.0, 1e-12);
}

TEST(OccupancyGrids, MemoryFollowsOccupiedVoxelsNotTheBox) {
  // A 1-unit cluster of points inside a box of side 100 (two lone far points stretch it),
  // at resolution 1024 and upsample 2: a dense bit grid over the box would take
  // 2048^3 / 8 bytes = 1 GiB; the sparse tree holds only the cluster's ~8k fine voxels.
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Eigen::Vector3d> pts{Eigen::Vector3d(-50, -50, -50), Eigen::Vector3d(50, 50, 50)};
  for (int i = 0; i < 20000; ++i) pts.emplace_back(u(rng), u(rng), u(rng));
  OccupancyOptions o;
  o.resolution = 1024;
  o.upsample = 2;
  const OccupancyGrids g = OccupancyGrids::fromSfm(pts, o);
  EXPECT_GT(g.sceneCount(), 4000u);
  EXPECT_LT(g.sceneCount(), 20000u);
  // OpenVDB's fixed cost is one 32^3-entry top internal node (~300 KB); leaves add
  // ~100 B per 8^3 block.
  std::printf("[ sparse memory ] %zu fine voxels in a 2048^3 box: scene VDB %.1f KB\n", g.sceneCount(),
              g.memory().scene_vdb / 1024.0);
  EXPECT_LT(g.memory().scene_vdb, std::size_t{4} << 20);
  EXPECT_LT(g.memory().total(), std::size_t{4} << 20);
}

TEST(OccupancyGrids, TrimPercentDropsOutliersFromTheBox) {
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < 1000; ++i) pts.emplace_back(u(rng), u(rng), u(rng));
  pts.emplace_back(100, 0.5, 0.5);  // far outliers
  pts.emplace_back(0.5, -50, 0.5);
  OccupancyOptions o;
  o.resolution = 10;
  o.trim_percent = 0.0;
  EXPECT_NEAR(OccupancyGrids::fromSfm(pts, o).box().max.x(), 100.0, 1e-12);
  o.trim_percent = 1.0;
  const OccupancyGrids g = OccupancyGrids::fromSfm(pts, o);
  for (int a = 0; a < 3; ++a) {
    std::vector<double> c;
    for (const auto& p : pts) c.push_back(p[a]);
    std::sort(c.begin(), c.end());
    const double n1 = static_cast<double>(c.size() - 1);
    EXPECT_EQ(g.box().min[a], c[static_cast<std::size_t>(std::floor(0.01 * n1))]);
    EXPECT_EQ(g.box().max[a], c[static_cast<std::size_t>(std::ceil(0.99 * n1))]);
  }
  EXPECT_LT(g.box().max.x(), 1.0);
  EXPECT_GT(g.box().min.y(), 0.0);
  EXPECT_NEAR(g.coarseVoxelSize(), g.box().size().maxCoeff() / 10, 1e-12);
}

TEST(OccupancyGrids, BadInputRaisesInputError) {
  const auto pts = unitBoxFrame();
  auto build = [](std::vector<Eigen::Vector3d> p, OccupancyOptions o) { return OccupancyGrids::fromSfm(p, o); };
  EXPECT_TRUE(test::throwsInputError([&] { build({}, {}); }, "SfM points", "points"));
  EXPECT_TRUE(test::throwsInputError(
      [&] {
        build({Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(1, 2, 3)}, {});
      },
      "SfM points", "points"));
  EXPECT_TRUE(test::throwsInputError(
      [&] {
        build({Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(NAN, 0, 0)}, {});
      },
      "SfM points", "point 1"));
  // One option out of range at a time, the others as OccupancyOptions has them: refused by name.
  const std::vector<std::pair<const char*, std::function<void(OccupancyOptions&)>>> bad_options = {
      {"resolution", [](OccupancyOptions& o) { o.resolution = 0; }},
      {"min_points", [](OccupancyOptions& o) { o.min_points = 0; }},
      {"upsample", [](OccupancyOptions& o) { o.upsample = 0; }},
      {"trim_percent", [](OccupancyOptions& o) { o.trim_percent = 50; }},
      {"dilation_radius", [](OccupancyOptions& o) { o.dilation_radius = -1; }}};
  for (const auto& [field, set] : bad_options) {
    OccupancyOptions o;
    set(o);
    EXPECT_TRUE(test::throwsInputError([&] { build(pts, o); }, "SfM points", field));
  }
  OccupancyGrids g = build(pts, {});
  const std::vector<Eigen::Vector3d> bad{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, INFINITY, 0)};
  EXPECT_TRUE(test::throwsInputError([&] { g.addObserved(bad); }, "SA-Points", "point 1"));
}

TEST(OccupancyGrids, EmptySceneGridIsValid) {
  // Every coarse voxel holds one point: nothing reaches m = 2.
  OccupancyOptions o;
  o.resolution = 10;
  OccupancyGrids g = OccupancyGrids::fromSfm(unitBoxFrame(), o);
  EXPECT_EQ(g.sceneCount(), 0u);
  EXPECT_EQ(g.coarseCount(), 0u);
  EXPECT_TRUE(g.sceneVoxelBounds().empty());
  EXPECT_EQ(g.observedFraction(), 0.0);
  g.addObserved(std::vector<Eigen::Vector3d>{Eigen::Vector3d(5, 5, 5)});
  EXPECT_EQ(g.observedCount(), 125u);  // one fine voxel dilated to the 5^3 cube
  EXPECT_EQ(g.observedFraction(), 0.0);
  EXPECT_TRUE(g.observedSceneVoxels().empty());
  g.addObserved({});
  EXPECT_EQ(g.observedCount(), 125u);
}

TEST(OccupancyGrids, ObservedVoxelsAreDilatedAndAccumulate) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 10);
  std::vector<Eigen::Vector3d> sfm = unitBoxFrame();
  for (int i = 0; i < 4000; ++i) sfm.emplace_back(u(rng), u(rng), 0.3 * u(rng));
  OccupancyOptions o;
  o.resolution = 20;
  o.upsample = 2;
  OccupancyGrids g = OccupancyGrids::fromSfm(sfm, o);
  ASSERT_GT(g.sceneCount(), 0u);
  const double h = g.voxelSize();

  std::vector<Eigen::Vector3d> sa;
  for (int i = 0; i < 300; ++i) sa.emplace_back(u(rng), u(rng), u(rng) * 0.5);
  // Points outside the box still mark voxels (negative indices).
  sa.emplace_back(-1.3, -0.2, 11.0);
  std::set<Voxel> marked;
  for (const auto& p : sa) {
    const Voxel v = g.voxelOf(p);
    for (int a = 0; a < 3; ++a) {
      // The voxel contains the point.
      EXPECT_LE(g.origin()[a] + h * v[a], p[a] + 1e-12);
      EXPECT_GT(g.origin()[a] + h * (v[a] + 1), p[a] - 1e-12);
    }
    marked.insert(v);
  }
  const std::set<Voxel> expect = bruteDilate(marked, 2, DilationShape::Cube);

  // Three calls with parts of the points equal one call with all of them.
  OccupancyGrids parts = g;
  parts.addObserved(std::span(sa).subspan(0, 100));
  parts.addObserved(std::span(sa).subspan(100, 150));
  parts.addObserved(std::span(sa).subspan(250));
  g.addObserved(sa);
  EXPECT_EQ(asSet(g.observedVoxels()), expect);
  EXPECT_EQ(asSet(parts.observedVoxels()), expect);
  EXPECT_EQ(g.observedCount(), expect.size());
  for (const Voxel& v : expect) EXPECT_TRUE(g.isObserved(v));

  // Observed fraction = |observed & scene| / |scene|, checked voxel by voxel.
  std::size_t both = 0;
  for (const Voxel& v : g.sceneVoxels().voxels()) both += expect.count(v);
  ASSERT_GT(both, 0u);
  ASSERT_LT(both, g.sceneCount());
  EXPECT_EQ(g.observedSceneVoxels().size(), both);
  EXPECT_DOUBLE_EQ(g.observedFraction(), static_cast<double>(both) / g.sceneCount());
  g.clearObserved();
  EXPECT_EQ(g.observedCount(), 0u);
  EXPECT_EQ(g.observedFraction(), 0.0);
  // The copy kept its own observed grid (deep copy).
  EXPECT_EQ(parts.observedCount(), expect.size());
}

// The first grid loads the OpenVDB module, and with it libopenvdb (the program and this
// test link neither: test_vdb_module.cpp checks the program's start).
TEST(VdbModule, AGridLoadsTheModuleAndOpenVdb) {
  const std::vector<Eigen::Vector3d> pts = {{0, 0, 0}, {1, 1, 1}, {1, 1, 1}};
  const OccupancyGrids g = OccupancyGrids::fromSfm(pts, OccupancyOptions{.resolution = 4, .min_points = 1});
  EXPECT_GT(g.sceneCount(), 0u);
  EXPECT_TRUE(std::filesystem::exists(vdbModulePath())) << vdbModulePath();
  bool openvdb = false;
  dl_iterate_phdr(
      [](dl_phdr_info* info, std::size_t, void* found) {
        if (info->dlpi_name && std::string(info->dlpi_name).find("libopenvdb") != std::string::npos)
          *static_cast<bool*>(found) = true;
        return 0;
      },
      &openvdb);
  EXPECT_TRUE(openvdb);
}
