#pragma once
// What a training run will hold in memory, estimated before it starts, so that a run too
// large for the machine is refused with the numbers instead of being killed, and a
// memory budget can cap the model's growth (apps/memory_budget.h).
#include <cstddef>
#include <vector>

#include "geometry/scene/scene.h"

namespace saresgs {

struct MemoryEstimate {
  double image_bytes = 0;         // decoded 8-bit images of every view trained on or evaluated
                                  // (the scene keeps them) and the float targets of the trained ones
  double buffer_bytes = 0;        // one step's per-pixel buffers at the largest view
  double process_bytes = 64e6;    // the program and its libraries (TBB, Embree, OpenVDB, OpenCV)
  double bytes_per_gaussian = 0;  // per model: parameters, gradients, Adam moments, the initial copy,
                                  // densification statistics, projection and tile pairs
  double models = 1;              // models held at once (an active run: the loop's and the final fit's)
  std::size_t initial_gaussians = 0;
  int views = 0, largest_width = 0, largest_height = 0;

  double fixedBytes() const { return image_bytes + buffer_bytes + process_bytes; }
  double modelBytes(std::size_t gaussians) const {
    return models * bytes_per_gaussian * static_cast<double>(gaussians);
  }
  double bytesFor(std::size_t gaussians) const { return fixedBytes() + modelBytes(gaussians); }
  // The most Gaussians whose run fits in `budget` bytes (0 when the fixed part does not).
  std::size_t gaussiansWithin(double budget) const;
};

// trained: the views trained on; evaluated: the views rendered for metrics; the model
// starts with initial_gaussians at SH degree max_sh_degree (its coefficients are held from
// the start). Checked against peak RSS: `saresgs train` on room360 at 512x384 (150 views,
// 12k Gaussians, 300 iterations) estimated 578 MB, measured 569 MB.
MemoryEstimate estimateTrainingMemory(const Scene& scene, const std::vector<int>& trained,
                                      const std::vector<int>& evaluated, std::size_t initial_gaussians,
                                      int max_sh_degree, int models = 1);

}  // namespace saresgs
