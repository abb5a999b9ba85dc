#pragma once
// What the synthetic-scene tests share: each layout built once, and measures of a layout.
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "geometry/synth/synthetic_scene.h"
#include "tests/common/synthetic_options.h"

namespace saresgs::synth_test {

// Scenes are immutable, so each layout is built once for all tests.
inline const SyntheticScene& scene(const std::string& layout, int w = 128, int h = 96) {
  static std::map<std::tuple<std::string, int, int>, SyntheticScene> cache;
  auto key = std::make_tuple(layout, w, h);
  auto it = cache.find(key);
  if (it == cache.end()) {
    it = cache.emplace(key, makeSyntheticScene(test::syntheticOptions(layout, w, h, /*seed=*/3))).first;
  }
  return it->second;
}

// Distance from each camera centre to its nearest other camera centre.
inline std::vector<double> nearestNeighbourDistances(const std::vector<Camera>& cams) {
  std::vector<double> d(cams.size(), std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < cams.size(); ++i)
    for (std::size_t j = 0; j < cams.size(); ++j)
      if (i != j) d[i] = std::min(d[i], (cams[i].center() - cams[j].center()).norm());
  return d;
}

inline double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}
inline Eigen::Vector3f vec3(const nlohmann::json& j) {
  return {j[0].get<float>(), j[1].get<float>(), j[2].get<float>()};
}

}  // namespace saresgs::synth_test
