#pragma once
// --threads N for a whole command (the CLI) or call (Python). The rasterizer's arena takes N from its options; this
// caps everything else TBB runs in the process (SSIM, Adam, the residual subset, image
// decoding, the Fisher chain) at the same N while the returned object lives, so a run or
// an ablation job given one thread uses one core (before, only the tile kernels obeyed
// and the loss stage of `bench step --threads 1` ran on every core). 0: no cap.
#include <cstddef>
#include <memory>

#include <tbb/global_control.h>

namespace saresgs {

inline std::unique_ptr<tbb::global_control> limitThreads(int threads) {
  if (threads <= 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                               static_cast<std::size_t>(threads));
}

}  // namespace saresgs
