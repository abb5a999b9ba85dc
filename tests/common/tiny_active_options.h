#pragma once
// The active-loop options of the nbv tests on the tiny dataset (tests/common/tiny_dataset.h):
// 2 initial views, 5 at the end, a few iterations per view, SH 0, exact coverage sets on a
// coarse grid.
#include "nbv/active_run.h"

namespace saresgs {

inline ActiveOptions tinyOptions(Method m) {
  ActiveOptions o;
  o.method = m;
  o.initial_views = 2;
  o.max_views = 5;
  o.interval = 6;
  o.total_iterations = 90;
  o.trainer.max_sh_degree = 0;
  o.trainer.densify.from_iter = 10;
  o.trainer.densify.interval = 10;
  o.prefilter.scoring.encoding = CoverageEncoding::Exact;
  o.prefilter.resolution = 24;
  o.progress_test_views = 1;
  o.seed = 5;
  return o;
}

}  // namespace saresgs
