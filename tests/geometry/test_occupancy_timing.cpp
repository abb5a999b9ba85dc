// Prints (never asserts) the cost of the prefilter's parts on a room360 scene at 256x192
// with ~12k simulated SfM points: grid build, observed dilation, frustum vs visible sets
// per candidate, hashed vs exact scoring, grid memory. Timings are medians of repeats;
// run alone for stable numbers: test_geometry --gtest_filter='OccupancyTiming.*'
#include <gtest/gtest.h>
#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>

#include "geometry/occupancy/candidate_sets.h"
#include "geometry/occupancy/coverage_score.h"
#include "geometry/occupancy/occupancy_grid.h"
#include "occupancy_test_support.h"

using namespace saresgs;

namespace {

double medianMs(int reps, const std::function<void()>& f) {
  std::vector<double> t;
  for (int i = 0; i < reps; ++i) {
    const auto a = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

}  // namespace

TEST(OccupancyTiming, Room360At256x192) {
  const auto& s = test::room360Sfm(256, 192, 12000);
  const auto& cams = s.scene.cameras;
  std::printf("[ occupancy timing ] room360 256x192, %zu SfM points, %zu cameras, %d threads\n",
              s.points.size(), cams.size(), tbb::info::default_concurrency());
  for (int res : {128, 256}) {
    OccupancyOptions o;
    o.resolution = res;
    o.min_points = 2;
    o.upsample = 2;
    std::optional<OccupancyGrids> g;
    const double t_build = medianMs(7, [&] { g.emplace(OccupancyGrids::fromSfm(s.points, o)); });
    // Observed: depth-map points of 8 train views (stand-ins for SA-Points), stride 2.
    std::vector<Eigen::Vector3d> sa;
    for (int k = 0; k < 8; ++k) {
      const Camera& cam = cams[s.scene.train[k * 9]];
      const ImageF depth = s.scene.renderDepth(cam);
      for (int v = 0; v < depth.height; v += 2)
        for (int u = 0; u < depth.width; u += 2)
          if (depth.at(u, v) > 0) sa.push_back(cam.unproject(Eigen::Vector2d(u + 0.5, v + 0.5), depth.at(u, v)));
    }
    const double t_obs = medianMs(5, [&] {
      g->clearObserved();
      g->addObserved(sa);
    });
    const VoxelSet obs = g->observedSceneVoxels();
    std::optional<VisibilityTracer> tracer;
    const double t_tracer = medianMs(3, [&] { tracer.emplace(*g); });

    std::vector<VoxelSet> fr(cams.size()), vis(cams.size());
    const double t_fr = medianMs(3, [&] {
      for (std::size_t j = 0; j < cams.size(); ++j) fr[j] = frustumSet(*g, cams[j]);
    }) / cams.size();
    const double t_vis4 = medianMs(3, [&] {
      for (std::size_t j = 0; j < cams.size(); ++j) vis[j] = tracer->visibleSet(cams[j], 4);
    }) / cams.size();
    const double t_vis1 = medianMs(1, [&] {
      for (std::size_t j = 0; j < cams.size(); ++j) tracer->visibleSet(cams[j], 1);
    }) / cams.size();
    double mean_fr = 0, mean_vis = 0;
    for (std::size_t j = 0; j < cams.size(); ++j) {
      mean_fr += fr[j].size();
      mean_vis += vis[j].size();
    }
    mean_fr /= cams.size();
    mean_vis /= cams.size();

    PrefilterOptions p;
    p.encoding = CoverageEncoding::Exact;
    const double t_exact = medianMs(5, [&] { scoreCandidates(obs, fr, g->sceneCount(), p); }) / cams.size();
    p.encoding = CoverageEncoding::Hashed;
    p.table_size = std::size_t{1} << 19;
    const double t_h19 = medianMs(5, [&] { scoreCandidates(obs, fr, g->sceneCount(), p); }) / cams.size();
    p.table_size = std::size_t{1} << 11;
    const double t_h11 = medianMs(5, [&] { scoreCandidates(obs, fr, g->sceneCount(), p); }) / cams.size();

    // The dense path: encode each candidate into T bits, XOR/popcount all T bits.
    const HashedBits ho = HashedBits::encode(obs, std::size_t{1} << 19);
    const double t_dense19 = medianMs(5, [&] {
      for (const VoxelSet& c : fr) scoreHashed(ho, HashedBits::encode(c, std::size_t{1} << 19));
    }) / cams.size();

    const GridMemory m = g->memory();
    std::printf(
        "  resolution %d x upsample 2: %zu coarse -> %zu fine scene voxels (voxel %.4f), "
        "observed %zu (%zu in scene, fraction %.3f from %zu points)\n"
        "    build scene grid %.2f ms | addObserved (dilate r=2 cube) %.2f ms | Embree voxel BVH %.2f ms\n"
        "    per candidate: frustum set %.3f ms (mean %.0f voxels) | visible set stride 4 %.3f ms "
        "(mean %.0f voxels), stride 1 %.3f ms\n"
        "    per candidate scoring vs observed: exact %.4f ms | hashed 2^19 %.4f ms | hashed 2^11 %.4f ms "
        "| hashed 2^19 dense bit vectors, 1 thread %.4f ms\n"
        "    memory: scene VDB %.1f KB, observed VDB %.1f KB, scene key index %.1f KB\n",
        res, g->coarseCount(), g->sceneCount(), g->voxelSize(), g->observedCount(), obs.size(),
        g->observedFraction(), sa.size(), t_build, t_obs, t_tracer, t_fr, mean_fr, t_vis4, mean_vis, t_vis1,
        t_exact, t_h19, t_h11, t_dense19, m.scene_vdb / 1024.0, m.observed_vdb / 1024.0, m.scene_index / 1024.0);
    EXPECT_GT(g->sceneCount(), 0u);
  }
}
