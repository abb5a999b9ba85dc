// scaledSchedule: the trainer's densification and SH schedules scaled for shorter runs.
#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>

#include "splat/train/schedule.h"

namespace saresgs {
namespace {

// Every TrainerOptions field that scaledSchedule must leave as it is.
void expectUnscaledFieldsEqual(const TrainerOptions& a, const TrainerOptions& b) {
  EXPECT_EQ(a.max_sh_degree, b.max_sh_degree);
  EXPECT_EQ(a.lr.means, b.lr.means);
  EXPECT_EQ(a.lr.log_scales, b.lr.log_scales);
  EXPECT_EQ(a.lr.rotations, b.lr.rotations);
  EXPECT_EQ(a.lr.opacities, b.lr.opacities);
  EXPECT_EQ(a.lr.sh_dc, b.lr.sh_dc);
  EXPECT_EQ(a.lr.sh_rest, b.lr.sh_rest);
  EXPECT_EQ(a.means_lr_final, b.means_lr_final);
  EXPECT_EQ(a.means_lr_steps, b.means_lr_steps);
  EXPECT_EQ(a.densify.enabled, b.densify.enabled);
  EXPECT_EQ(a.densify.grad_threshold, b.densify.grad_threshold);
  EXPECT_EQ(a.densify.percent_dense, b.densify.percent_dense);
  EXPECT_EQ(a.densify.min_opacity, b.densify.min_opacity);
  EXPECT_EQ(a.densify.max_screen_radius, b.densify.max_screen_radius);
  EXPECT_EQ(a.densify.max_world_scale, b.densify.max_world_scale);
  EXPECT_EQ(a.densify.split_count, b.densify.split_count);
  EXPECT_EQ(a.densify.max_gaussians, b.densify.max_gaussians);
  EXPECT_EQ(a.residual.enabled, b.residual.enabled);
  EXPECT_EQ(a.residual.alpha, b.residual.alpha);
  EXPECT_EQ(a.residual.beta, b.residual.beta);
  EXPECT_EQ(a.residual.lambda_full, b.residual.lambda_full);
  EXPECT_EQ(a.residual.lambda_sub, b.residual.lambda_sub);
  EXPECT_EQ(a.residual.sub_only, b.residual.sub_only);
  EXPECT_EQ(a.residual.ranking, b.residual.ranking);
  EXPECT_EQ(a.raster.sh_degree, b.raster.sh_degree);
  EXPECT_EQ(a.raster.near_plane, b.raster.near_plane);
  EXPECT_EQ(a.raster.guard_band, b.raster.guard_band);
  EXPECT_EQ(a.raster.eps2d, b.raster.eps2d);
  EXPECT_EQ(a.raster.extent, b.raster.extent);
  EXPECT_EQ(a.raster.background, b.raster.background);
  EXPECT_EQ(a.raster.execution.threads, b.raster.execution.threads);
  EXPECT_EQ(a.raster.execution.kernels, b.raster.execution.kernels);
  EXPECT_EQ(a.lambda_ssim, b.lambda_ssim);
  EXPECT_EQ(a.random_init_points, b.random_init_points);
  EXPECT_EQ(a.initial_opacity, b.initial_opacity);
  EXPECT_EQ(a.seed, b.seed);
}

// A quarter of 3DGS's schedule is the active loop's quick preset (nbv/preset.cpp): 125,
// 25, 750, 3750 and 250, and a reset guard of one (scaled) reset interval, 750.
TEST(ScaledSchedule, QuarterOfTheDefaultsIsTheQuickSchedule) {
  const TrainerOptions defaults;
  const TrainerOptions q = scaledSchedule(defaults, 0.25);
  EXPECT_EQ(q.densify.from_iter, 125);
  EXPECT_EQ(q.densify.interval, 25);
  EXPECT_EQ(q.densify.opacity_reset_interval, 750);
  EXPECT_EQ(q.densify.until_iter, 3750);
  EXPECT_EQ(q.densify.min_iterations_after_reset, 750);
  EXPECT_EQ(q.sh_interval, 250);
  expectUnscaledFieldsEqual(q, defaults);
}

TEST(ScaledSchedule, KeepsOtherFieldsOfTheBase) {
  TrainerOptions base;
  base.seed = 7;
  base.max_sh_degree = 1;
  base.densify.max_gaussians = 40000;
  base.residual.enabled = true;
  base.raster.execution.threads = 2;
  base.raster.background = {1.0f, 0.5f, 0.0f};
  const TrainerOptions s = scaledSchedule(base, 2.0);
  EXPECT_EQ(s.densify.from_iter, 1000);
  EXPECT_EQ(s.densify.until_iter, 30000);
  EXPECT_EQ(s.sh_interval, 2000);
  expectUnscaledFieldsEqual(s, base);
}

TEST(ScaledSchedule, RoundsAndKeepsIntervalsPositive) {
  TrainerOptions base;
  base.densify.from_iter = 3;  // 0.3 rounds to 0
  const TrainerOptions s = scaledSchedule(base, 0.1);
  EXPECT_EQ(s.densify.from_iter, 0);
  EXPECT_EQ(s.densify.interval, 10);
  EXPECT_EQ(s.densify.min_iterations_after_reset, 300);
  const TrainerOptions tiny = scaledSchedule(TrainerOptions{}, 1e-4);
  EXPECT_EQ(tiny.densify.interval, 1);
  EXPECT_EQ(tiny.densify.opacity_reset_interval, 1);
  EXPECT_EQ(tiny.sh_interval, 1);
  EXPECT_EQ(tiny.densify.until_iter, 2);  // 1.5 rounds away from zero
  TrainerOptions off;
  off.sh_interval = 0;  // 0: every degree at once; stays 0
  off.densify.opacity_reset_interval = 0;
  const TrainerOptions o = scaledSchedule(off, 0.5);
  EXPECT_EQ(o.sh_interval, 0);
  EXPECT_EQ(o.densify.opacity_reset_interval, 0);
}

TEST(ScaledSchedule, RejectsFactorsThatAreNotPositive) {
  EXPECT_THROW(scaledSchedule(TrainerOptions{}, 0.0), std::invalid_argument);
  EXPECT_THROW(scaledSchedule(TrainerOptions{}, -1.0), std::invalid_argument);
  EXPECT_THROW(scaledSchedule(TrainerOptions{}, std::numeric_limits<double>::infinity()), std::invalid_argument);
}

}  // namespace
}  // namespace saresgs
