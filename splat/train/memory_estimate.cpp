#include "splat/train/memory_estimate.h"

#include <algorithm>
#include <set>

namespace saresgs {

std::size_t MemoryEstimate::gaussiansWithin(double budget) const {
  const double left = budget - fixedBytes();
  if (left <= 0 || bytes_per_gaussian <= 0 || models <= 0) return 0;
  return static_cast<std::size_t>(left / (models * bytes_per_gaussian));
}

MemoryEstimate estimateTrainingMemory(const Scene& scene, const std::vector<int>& trained,
                                      const std::vector<int>& evaluated, std::size_t initial_gaussians,
                                      int max_sh_degree, int models) {
  MemoryEstimate e;
  e.models = models;
  e.initial_gaussians = initial_gaussians;
  std::set<int> all(trained.begin(), trained.end());
  all.insert(evaluated.begin(), evaluated.end());
  for (int v : all) {
    if (v < 0 || static_cast<std::size_t>(v) >= scene.views.size()) continue;
    const Intrinsics& K = scene.views[static_cast<std::size_t>(v)].camera.K;
    const double px = static_cast<double>(K.width) * K.height;
    e.image_bytes += 3.0 * px;  // the scene's 8-bit copy (the trainer's float target is one buffer)
    if (px > static_cast<double>(e.largest_width) * e.largest_height) {
      e.largest_width = K.width;
      e.largest_height = K.height;
    }
    ++e.views;
  }
  // A step's per-pixel state: render outputs (rgb, alpha, depth, contributors, final T,
  // walk), the loss and its gradient, SSIM's five filtered planes and their gradients,
  // a residual branch's second render, the float target: about 63 floats. Then 2x for what the allocator
  // keeps between steps.
  e.buffer_bytes = 2.0 * 63.0 * 4.0 * static_cast<double>(e.largest_width) * e.largest_height;
  // Per Gaussian: 11 + 3 (deg + 1)^2 floats held five times (model, gradient, two Adam
  // moments, initial copy), densification statistics (4 floats), the projection and tile
  // data (about 60 floats) and tile pairs (about 8 tiles of 14 floats: slots and lists).
  const int sh = 3 * (max_sh_degree + 1) * (max_sh_degree + 1);
  e.bytes_per_gaussian = 4.0 * (5.0 * (11 + sh) + 4 + 60 + 8 * 14);
  return e;
}

}  // namespace saresgs
