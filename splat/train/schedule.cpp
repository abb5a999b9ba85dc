#include "splat/train/schedule.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace saresgs {

TrainerOptions scaledSchedule(TrainerOptions base, double factor) {
  if (!(factor > 0) || !std::isfinite(factor))
    throw std::invalid_argument("scaledSchedule: the factor must be positive and finite");
  auto scaled = [&](int v) { return static_cast<int>(std::lround(v * factor)); };
  auto scaledInterval = [&](int v) { return v > 0 ? std::max(1, scaled(v)) : v; };
  DensifyOptions& d = base.densify;
  d.from_iter = scaled(d.from_iter);
  d.interval = scaledInterval(d.interval);
  d.opacity_reset_interval = scaledInterval(d.opacity_reset_interval);
  d.until_iter = scaled(d.until_iter);
  d.min_iterations_after_reset = scaled(d.min_iterations_after_reset);
  base.sh_interval = scaledInterval(base.sh_interval);
  return base;
}

}  // namespace saresgs
