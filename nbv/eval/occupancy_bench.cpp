#include "nbv/eval/occupancy_bench.h"

#include <nlohmann/json.hpp>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <optional>
#include <vector>

#include "geometry/occupancy/candidate_sets.h"
#include "geometry/occupancy/coverage_score.h"
#include "geometry/occupancy/occupancy_grid.h"
#include "geometry/synth/simulated_sfm.h"
#include "geometry/synth/synthetic_scene.h"
#include "geometry/synth/write_dataset.h"
#include "splat/bench/machine.h"
#include "splat/thread_limit.h"

namespace saresgs {

namespace {

// The median of `reps` runs of f, in milliseconds.
double medianMs(int reps, const std::function<void()>& f) {
  std::vector<double> t;
  for (int i = 0; i < reps; ++i) {
    const auto a = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
  }
  return sampleMedian(std::move(t));
}

}  // namespace

nlohmann::json benchOccupancy(const OccupancyBenchOptions& a) {
  const std::string load_before = loadAverage();
  const auto thread_limit = limitThreads(a.threads);
  const int threads =
      std::min<int>(tbb::info::default_concurrency(),
                    static_cast<int>(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)));

  // A room360 scene and what COLMAP would give for it.
  SyntheticOptions so;
  so.layout = "room360";
  so.width = a.width;
  so.height = a.height;
  so.seed = a.seed;
  const SyntheticScene scene = makeSyntheticScene(so);
  ColmapModel model = colmapModelOf(scene);
  SimulatedSfmOptions sim;
  sim.max_points = a.points;
  sim.candidates = 4 * a.points;
  sim.seed = a.seed;
  simulateSfm(scene, model, sim);
  std::vector<Eigen::Vector3d> sfm;
  for (const auto& [id, p] : model.points) sfm.push_back(p.xyz);
  const std::vector<Camera>& cams = scene.cameras;

  OccupancyOptions o;
  o.resolution = a.resolution;
  o.min_points = a.min_points;
  o.upsample = a.upsample;
  std::optional<OccupancyGrids> g;
  const double t_build = medianMs(7, [&] { g.emplace(OccupancyGrids::fromSfm(sfm, o)); });
  // Observed: depth-map points of 8 train views spread over the split (stand-ins for
  // SA-Points), every second pixel.
  std::vector<Eigen::Vector3d> sa;
  const std::size_t views = std::min<std::size_t>(8, scene.train.size());
  for (std::size_t k = 0; k < views; ++k) {
    const Camera& cam = cams[scene.train[k * scene.train.size() / views]];
    const ImageF depth = scene.renderDepth(cam);
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

  // Per candidate: every camera of the scene is a candidate.
  const double n = static_cast<double>(cams.size());
  std::vector<VoxelSet> fr(cams.size()), vis(cams.size());
  const double t_fr = medianMs(3,
                               [&] {
                                 for (std::size_t j = 0; j < cams.size(); ++j) fr[j] = frustumSet(*g, cams[j]);
                               }) /
                      n;
  const double t_vis4 = medianMs(3,
                                 [&] {
                                   for (std::size_t j = 0; j < cams.size(); ++j)
                                     vis[j] = tracer->visibleSet(cams[j], 4);
                                 }) /
                        n;
  const double t_vis1 = medianMs(1,
                                 [&] {
                                   for (std::size_t j = 0; j < cams.size(); ++j) tracer->visibleSet(cams[j], 1);
                                 }) /
                        n;
  double mean_fr = 0, mean_vis = 0;
  for (std::size_t j = 0; j < cams.size(); ++j) {
    mean_fr += static_cast<double>(fr[j].size());
    mean_vis += static_cast<double>(vis[j].size());
  }

  CoverageScoring p;
  p.encoding = CoverageEncoding::Exact;
  const double t_exact = medianMs(5, [&] { scoreCandidates(obs, fr, g->sceneCount(), p); }) / n;
  p.encoding = CoverageEncoding::Hashed;
  p.table_size = std::size_t{1} << 19;
  const double t_h19 = medianMs(5, [&] { scoreCandidates(obs, fr, g->sceneCount(), p); }) / n;
  p.table_size = std::size_t{1} << 11;
  const double t_h11 = medianMs(5, [&] { scoreCandidates(obs, fr, g->sceneCount(), p); }) / n;
  // The dense path, on one thread: encode each candidate into T bits, XOR/popcount all T.
  const HashedBits ho = HashedBits::encode(obs, std::size_t{1} << 19);
  const double t_dense19 = medianMs(5,
                                    [&] {
                                      for (const VoxelSet& c : fr)
                                        scoreHashed(ho, HashedBits::encode(c, std::size_t{1} << 19));
                                    }) /
                           n;
  const GridMemory m = g->memory();

  nlohmann::json j;
  j["benchmark"] = "occupancy";
  j["layout"] = "room360";
  j["width"] = a.width;
  j["height"] = a.height;
  j["sfm_points"] = sfm.size();
  j["cameras"] = cams.size();
  j["resolution"] = a.resolution;
  j["upsample"] = a.upsample;
  j["min_points"] = a.min_points;
  j["threads"] = threads;
  j["coarse_voxels"] = g->coarseCount();
  j["scene_voxels"] = g->sceneCount();
  j["voxel_size"] = g->voxelSize();
  j["observed_points"] = sa.size();
  j["observed_voxels"] = g->observedCount();
  j["observed_scene_voxels"] = obs.size();
  j["observed_fraction"] = g->observedFraction();
  j["mean_frustum_voxels"] = mean_fr / n;
  j["mean_visible_voxels"] = mean_vis / n;
  j["stage_ms"] = {{"scene_grid", t_build}, {"add_observed", t_obs}, {"embree_bvh", t_tracer}};
  j["per_candidate_ms"] = {{"frustum_set", t_fr},
                           {"visible_set_stride4", t_vis4},
                           {"visible_set_stride1", t_vis1},
                           {"score_exact", t_exact},
                           {"score_hashed_2pow19", t_h19},
                           {"score_hashed_2pow11", t_h11},
                           {"score_dense_2pow19_1thread", t_dense19}};
  j["memory_kb"] = {{"scene_vdb", m.scene_vdb / 1024.0},
                    {"observed_vdb", m.observed_vdb / 1024.0},
                    {"scene_index", m.scene_index / 1024.0}};
  nameMachine(j, load_before);
  return j;
}

}  // namespace saresgs
