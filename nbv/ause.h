#pragma once
// Area Under the Sparsification Error (AUSE), as FisherRF and the paper evaluate depth
// uncertainty: pixels sorted by uncertainty (most uncertain first) are removed in
// fractions 0, 0.01, ..., 0.99; after each removal the mean absolute depth error of the
// rest is taken. The oracle removes pixels by their true error. Both curves are
// normalised by the error at fraction 0, and AUSE is the mean difference between them
// (the area between the curves on [0, 1)). 0 = uncertainty ranks errors perfectly.
#include <optional>
#include <vector>

#include "splat/train/trainer.h"

namespace saresgs {

struct SparsificationCurves {
  std::vector<double> fraction, by_uncertainty, oracle;  // normalised
  double ause = 0;
};

// error and uncertainty per pixel (only the pixels to evaluate). Returns nullopt when
// fewer than 100 pixels are given or the total error is 0 (the curve is undefined).
// Ties in uncertainty break by pixel index, so the result is deterministic.
std::optional<SparsificationCurves> sparsification(const std::vector<double>& error,
                                                   const std::vector<double>& uncertainty, int steps = 100);

// AUSE of the trainer's depth against ground truth on `views` (mean over views with
// depth), uncertainty rendered from the diagonal Fisher information of `train_views`;
// nullopt when no view has depth.
std::optional<double> depthAuse(const Trainer& t, const std::vector<int>& train_views, const std::vector<int>& views,
                                double lambda = 1e-6);

}  // namespace saresgs
