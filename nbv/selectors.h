#pragma once
// View selectors that need neither grids nor SA-Points: random, farthest view sampling
// and FisherRF's information gain. Each takes the views chosen so far and the remaining
// candidates (indices into scene.views) and returns candidate scores or a choice; ties
// go to the lowest view index, so choices are deterministic.
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "geometry/scene/scene.h"
#include "splat/gaussians.h"
#include "splat/rasterize.h"

namespace saresgs {

int selectRandom(const std::vector<int>& candidates, std::mt19937_64& rng);

enum class ViewDistance { kEuclidean, kGreatCircle };

// Farthest view sampling: per candidate, the distance of its camera centre to the
// nearest chosen one (Euclidean, or the angle between directions from `center`, the
// great-circle distance on a sphere about the scene).
std::vector<double> farthestViewScores(const Scene& scene, const std::vector<int>& chosen,
                                       const std::vector<int>& candidates, ViewDistance metric,
                                       const Eigen::Vector3d& center);

// FisherRF: H_train from `chosen`, then each candidate's sum H_v / (H_train + lambda).
// Candidates are streamed through one information buffer: memory does not grow with
// their number. `tick(done, total)` is called before each candidate (and at the end).
std::vector<double> fisherScores(const Gaussians& g, const RasterSettings& s, const Scene& scene,
                                 const std::vector<int>& chosen, const std::vector<int>& candidates,
                                 double lambda = 1e-6, const std::function<void(int, int)>& tick = {});

// Index (into candidates) of the highest score; ties to the lowest view index.
std::size_t argmaxScore(const std::vector<double>& scores, const std::vector<int>& candidates);

}  // namespace saresgs
