#pragma once
// The path-variance selector (`--method path-variance`): the view that most reduces the
// model's predicted variance summed over the pool of path views, the stand-in for the
// views a person will look at (splat/fisher.h: pathVarianceScore). The pool is the train
// views (the held ones and every candidate), so W = H_held + the candidates' information:
// one more sum in the candidate pass FisherRF already runs. Occlusion comes from the
// rasterizer's information, so a view whose content hides behind a wall brings nothing.
#include <functional>
#include <vector>

#include "geometry/scene/scene.h"
#include "splat/fisher.h"

namespace saresgs {

struct PathVarianceOptions {
  double lambda = 1e-6;  // the damping floor (FisherRF's lambda)
  // Each parameter group's damping is kappa x the median of its nonzero held information
  // (relativeDamping); 0 keeps the single lambda.
  double kappa = 0.01;
  // The candidates' information kept between the pass that sums W and the one that
  // scores; past this many bytes the rest are computed again (a second pass for them).
  std::size_t keep_bytes = std::size_t{1} << 30;
};

// One score per candidate (pathVarianceScore against the held views' information, W over
// the held views and the candidates). `tick(done, total)` as fisherScores'.
std::vector<double> pathVarianceScores(const Gaussians& g, const RasterSettings& s, const Scene& scene,
                                       const std::vector<int>& chosen, const std::vector<int>& candidates,
                                       const PathVarianceOptions& opt, const std::function<void(int, int)>& tick = {});

}  // namespace saresgs
