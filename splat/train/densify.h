#pragma once
// Adaptive density control as 3DGS does it: Gaussians whose mean view-space (NDC)
// gradient exceeds a threshold are cloned when small and split in two when large;
// Gaussians that are nearly transparent or too big are pruned; opacities are reset
// periodically. The schedule (from, until, interval, reset) is a parameter, so the
// active loop can restart it.
#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include "splat/gaussians.h"
#include "splat/train/adam.h"

namespace saresgs {

struct DensifyOptions {
  bool enabled = true;
  int from_iter = 500;
  int until_iter = 15000;
  int interval = 100;
  int opacity_reset_interval = 3000;
  float grad_threshold = 2e-4f;  // mean |dL/d mean2d| in NDC units
  float percent_dense = 0.01f;   // clone below, split above this fraction of extent
  float min_opacity = 0.005f;    // prune below
  float max_screen_radius = 20;  // px; prunes only after the first opacity reset
  float max_world_scale = 0.1f;  // fraction of extent; likewise
  int split_count = 2;
  // 0: unlimited; otherwise no growth beyond it: when the candidates would exceed it, the
  // ones with the largest mean gradient are kept (keepLargestGradients).
  std::size_t max_gaussians = 0;
  // An opacity reset needs iterations after it to recover: it is skipped when fewer than
  // this many remain in the trainer's plan (Trainer::planUntil, or the train() call).
  // The default is one reset interval, the recovery time 3DGS gives its model before the
  // next reset; so a phase shorter than that (every phase of an active run's quick
  // preset, and a 3000-iteration fit) is never left with a transparent model.
  int min_iterations_after_reset = 3000;
};

// Per-Gaussian statistics gathered between densification steps.
struct DensifyStats {
  std::vector<float> grad_accum;    // sum of |2D-mean gradient| in NDC units
  std::vector<std::int32_t> count;  // iterations in which the Gaussian was visible
  std::vector<float> max_radius;    // px
  void resize(std::size_t n) {
    grad_accum.assign(n, 0.0f);
    count.assign(n, 0);
    max_radius.assign(n, 0.0f);
  }
};

// Adds one iteration's statistics. grad_mean2d is in pixels (2 per Gaussian); the NDC
// gradient is that times (W/2, H/2), the unit 3DGS's threshold is given in.
void accumulateDensifyStats(DensifyStats& st, const std::vector<float>& grad_mean2d, std::span<const float> radii,
                            std::span<const std::uint8_t> visible, int width, int height);

// Under the cap (opt.max_gaussians, the model holding n): keeps, of the clone and split
// candidates, those with the largest mean 2D gradient (ties to the lower index) whose
// added Gaussians fit; both lists stay in index order. 3DGS's budgeted variants (e.g.
// Taming 3DGS) likewise spend a fixed budget on the highest-scoring candidates; the
// gradient is the score 3DGS's own densification already thresholds.
void keepLargestGradients(std::vector<int>& clone, std::vector<int>& split, const std::vector<float>& mean_grad,
                          std::size_t n, const DensifyOptions& opt);

struct DensifyReport {
  std::size_t cloned = 0, split = 0, pruned = 0;
};

// Clones, splits, then prunes. New Gaussians get zero Adam moments (as 3DGS appends
// them to the optimiser); the stats are reset for the new model. `prune_big` enables
// the screen- and world-size pruning (3DGS: after the first opacity reset).
DensifyReport densifyAndPrune(Gaussians& g, AdamState& adam, DensifyStats& st, const DensifyOptions& opt, double extent,
                              bool prune_big, std::mt19937_64& rng);

// Opacity <- min(opacity, 0.01), with its Adam moments zeroed (3DGS's reset).
void resetOpacity(Gaussians& g, AdamState& adam, float ceiling = 0.01f);

}  // namespace saresgs
