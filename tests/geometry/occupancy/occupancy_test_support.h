#pragma once
// Shared inputs of the occupancy tests: a small room360 synthetic scene with simulated
// SfM points (what COLMAP would give), built once per test process.
#include <Eigen/Core>
#include <map>
#include <tuple>
#include <vector>

#include "geometry/synth/simulated_sfm.h"
#include "geometry/synth/synthetic_scene.h"
#include "geometry/synth/write_dataset.h"

namespace saresgs::test {

struct SfmScene {
  SyntheticScene scene;
  std::vector<Eigen::Vector3d> points;  // simulated SfM points (with ~3 % outliers)
};

inline const SfmScene& room360Sfm(int width = 128, int height = 96, std::size_t max_points = 6000) {
  static std::map<std::tuple<int, int, std::size_t>, SfmScene> cache;
  const auto key = std::make_tuple(width, height, max_points);
  auto it = cache.find(key);
  if (it == cache.end()) {
    SyntheticOptions o;
    o.layout = "room360";
    o.width = width;
    o.height = height;
    o.seed = 5;
    SfmScene s{makeSyntheticScene(o), {}};
    ColmapModel model = colmapModelOf(s.scene);
    SimulatedSfmOptions sim;
    sim.max_points = max_points;
    sim.candidates = 4 * max_points;
    sim.seed = 5;
    simulateSfm(s.scene, model, sim);
    for (const auto& [id, p] : model.points) s.points.push_back(p.xyz);
    it = cache.emplace(key, std::move(s)).first;
  }
  return it->second;
}

}  // namespace saresgs::test
