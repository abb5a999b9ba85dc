#pragma once
// One selection step as a method sees it, and each method's way of choosing from it (the
// `select` of its row in the method registry, nbv/method_table.cpp). ActiveRun::selectNext
// builds the step (the candidates; for the coverage methods the SA-Point prefilter's
// scores and cut, which need the run's state) and calls the method's function; a new
// selector is its row there plus its function here, with its algorithm in a file of its own.
#include <functional>
#include <random>
#include <vector>

#include "nbv/active_options.h"

namespace saresgs {

struct SelectionStep {
  const Scene& scene;
  const Trainer& trainer;
  const ActiveOptions& options;
  const std::vector<int>& held;
  const std::vector<int>& candidates;   // every train view not held
  std::vector<int> pool;                // what Fisher ranks: the candidates, or the prefilter's cut
  const std::vector<double>& coverage;  // the prefilter's score per candidate (coverage methods), else empty
  std::mt19937_64& rng;
  SurfaceCoverage* surface;  // the hybrid's visible-surface sets, when it uses them
  std::function<void(ActivePhase, int, int)> report;
};

// The methods' functions (SelectFn): each fills the log (candidates, scores, seconds) and
// returns the chosen view.
int selectRandomView(SelectionStep& step, SelectionLog& log);
int selectFarthestView(SelectionStep& step, SelectionLog& log);
int selectKmedianView(SelectionStep& step, SelectionLog& log);
int selectOracleView(SelectionStep& step, SelectionLog& log);
int selectPathVarianceView(SelectionStep& step, SelectionLog& log);
int selectCoverageView(SelectionStep& step, SelectionLog& log);
// FisherRF's gain on the pool (trace, log-det or the hybrid's criterion by method), with
// the fisher-kmedian weighting and the hybrid's coverage evidence where the method asks.
int selectFisherView(SelectionStep& step, SelectionLog& log);
// A pose gate (k-median gain or distance to the nearest held view) keeps the top
// ActiveOptions::gate_keep of the candidates, which selectFisherView then ranks.
int selectGatedFisherView(SelectionStep& step, SelectionLog& log);
// The caller's function (ActiveOptions::custom_selector).
int selectCustomView(SelectionStep& step, SelectionLog& log);

}  // namespace saresgs
