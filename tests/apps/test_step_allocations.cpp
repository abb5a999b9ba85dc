// A training step allocates nothing once its sizes have been seen: viewLossAndGradient
// with kept StepBuffers (renders, loss images, the residual subset) and the rasterizer's
// and loss's per-thread scratch, counted by the binary's operator new (apps/heap_count.h,
// compiled into this test program as into the CLI). One thread, so that no TBB worker
// meets its kept scratch for the first time in a later call.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <random>
#include <vector>

#include "apps/heap_count.h"
#include "common/pinhole.h"
#include "splat/rasterize.h"
#include "splat/train/trainer.h"

using namespace saresgs;

namespace {

Camera camera(int w, int h) {
  const Intrinsics K = test::pinhole(w, h, 0.9 * w);
  return Camera::lookAt(K, Eigen::Vector3d(0.3, -3.0, 0.5), Eigen::Vector3d(0, 0, 0), Eigen::Vector3d::UnitZ());
}

Gaussians scene(int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> nd(0, 1);
  Gaussians g;
  g.max_sh_degree = 2;
  g.resize(static_cast<std::size_t>(n));
  for (auto& x : g.means) x = 0.8f * nd(rng);
  for (auto& x : g.log_scales) x = -2.3f + 0.3f * nd(rng);
  for (auto& x : g.rotations) x = nd(rng);
  for (auto& x : g.opacities) x = nd(rng);
  for (auto& x : g.sh) x = 0.4f * nd(rng);
  return g;
}

// Allocations of the `calls` steps after the first `warmup`.
std::uint64_t stepAllocations(bool residual, bool sub_only, int warmup, int calls) {
  const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  const Gaussians g = scene(1500, 3);
  const Camera cam = camera(96, 72);
  RasterSettings s;
  s.sh_degree = 2;
  s.execution.threads = 1;
  const ImageF target = rasterize(scene(1500, 4), cam, s).rgb;
  ResidualOptions res;
  res.enabled = residual;
  res.sub_only = sub_only;
  std::mt19937_64 rng(5);
  Gaussians grad = g.zerosLike();
  std::vector<float> grad2d(2 * g.size(), 0.0f);
  StageSeconds secs;
  StepBuffers buffers;
  std::uint64_t before = 0;
  for (int k = 0; k < warmup + calls; ++k) {
    if (k == warmup) before = apps::heapAllocations();
    const ViewLoss L = viewLossAndGradient(g, cam, s, target, 0.2, res, rng, grad, grad2d, secs, buffers);
    EXPECT_TRUE(std::isfinite(L.loss));
  }
  return apps::heapAllocations() - before;
}

TEST(StepAllocations, NoneOnceTheSizesHaveBeenSeen) {
  EXPECT_EQ(stepAllocations(false, false, 1, 5), 0u) << "plain step";
  EXPECT_EQ(stepAllocations(true, false, 1, 5), 0u) << "residual step (both branches)";
  EXPECT_EQ(stepAllocations(true, true, 1, 5), 0u) << "residual step (subset only)";
}

TEST(StepAllocations, TheCounterSeesAFreshStepsBuffers) {
  // The property above can fail: a step with new buffers every time allocates its
  // renders and loss images again.
  const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  const Gaussians g = scene(500, 6);
  const Camera cam = camera(48, 36);
  RasterSettings s;
  s.execution.threads = 1;
  const ImageF target = rasterize(scene(500, 7), cam, s).rgb;
  std::mt19937_64 rng(1);
  Gaussians grad = g.zerosLike();
  std::vector<float> grad2d(2 * g.size(), 0.0f);
  StageSeconds secs;
  {
    StepBuffers warm;
    viewLossAndGradient(g, cam, s, target, 0.2, {}, rng, grad, grad2d, secs, warm);
  }
  const std::uint64_t before = apps::heapAllocations();
  StepBuffers fresh;
  viewLossAndGradient(g, cam, s, target, 0.2, {}, rng, grad, grad2d, secs, fresh);
  EXPECT_GE(apps::heapAllocations() - before, 4u);  // at least the rgb, alpha, depth and loss images
}

}  // namespace
