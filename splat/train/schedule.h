#pragma once
// The trainer's iteration schedules for runs of another length than 3DGS's 30000
// iterations.
#include "splat/train/trainer.h"

namespace saresgs {

// `base` with its densification and SH schedules scaled by `factor` (> 0):
// densify.from_iter, densify.interval, densify.opacity_reset_interval, densify.until_iter,
// densify.min_iterations_after_reset and sh_interval, each rounded to the nearest integer
// (halves away from zero). The three intervals stay at least 1 when positive (0 would
// switch densification, opacity resets or the SH schedule off). Everything else, the
// learning-rate decay included, is unchanged. Throws std::invalid_argument for a factor
// that is not positive and finite.
TrainerOptions scaledSchedule(TrainerOptions base, double factor);

}  // namespace saresgs
