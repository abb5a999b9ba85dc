#pragma once
// The active run on test::ringScene whose checkpoints are committed as fuzz regression
// inputs: the fuzz fixture's run (fuzz/fuzz_fixtures.cpp) and the tests that replay those
// checkpoints start from the same options. Free of GoogleTest, as ring_scene.h.
#include "nbv/active_run.h"

namespace saresgs::test {

// Random selection from 2 views to 4, one iteration per view held, 8 in all, SH degree 1,
// seed 5; the rest as ActiveOptions has it.
inline ActiveOptions ringRunOptions() {
  ActiveOptions o;
  o.method = Method::kRandom;
  o.initial_views = 2;
  o.max_views = 4;
  o.interval = 1;
  o.total_iterations = 8;
  o.trainer.max_sh_degree = 1;
  o.seed = 5;
  return o;
}

}  // namespace saresgs::test
