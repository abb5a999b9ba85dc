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
// The fvs method's scores: about the mean of the train cameras' centres.
std::vector<double> fvsScores(const Scene& scene, const std::vector<int>& chosen, const std::vector<int>& candidates,
                              ViewDistance metric = ViewDistance::kEuclidean);

// How a candidate's information is scored against H_train (splat/fisher.h): FisherRF's
// trace, sum H_v / (H_train + lambda), or the D-optimal log-det gain,
// sum log(1 + H_v / (H_train + lambda)).
enum class FisherCriterion { kTrace, kLogDet };

// FisherRF: H_train from `chosen`, then each candidate's score by `criterion`.
// Candidates are streamed through one information buffer: memory does not grow with
// their number. `tick(done, total)` is called before each candidate (and at the end).
std::vector<double> fisherScores(const Gaussians& g, const RasterSettings& s, const Scene& scene,
                                 const std::vector<int>& chosen, const std::vector<int>& candidates,
                                 double lambda = 1e-6, const std::function<void(int, int)>& tick = {},
                                 FisherCriterion criterion = FisherCriterion::kTrace);

// The second kind of evidence of the hybrid: Embree-visible SfM surface no held view has
// seen (nbv/surface_coverage.h), or the distance of the candidate's camera to the nearest
// held one (farthest view sampling's score).
// Or the facility-location gain over the train views (SurfaceCoverage::facilityGain).
enum class HybridCoverage { kSurface, kViewDistance, kFacility };

// The hybrid score of two kinds of evidence: (1 - w) F / max F + w N / max N over the
// candidates, F the Fisher scores and N the new-surface counts (a term whose maximum is
// not positive, or not finite, contributes 0). Scale-free in both, so w is the share of
// the decision each kind of evidence gets. Throws std::invalid_argument on mismatched
// sizes or w outside [0, 1].
std::vector<double> hybridScores(const std::vector<double>& fisher, const std::vector<double>& new_surface, double w);

// Index (into candidates) of the highest score; ties to the lowest view index.
std::size_t argmaxScore(const std::vector<double>& scores, const std::vector<int>& candidates);

}  // namespace saresgs
