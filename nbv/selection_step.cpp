#include "nbv/selection_step.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>

#include "nbv/path_variance.h"
#include "nbv/selection_seconds.h"

namespace saresgs {

namespace {

using Clock = std::chrono::steady_clock;

// The candidates' scores in the log and the best of them.
int best(const std::vector<int>& candidates, std::vector<double> scores, SelectionLog& log) {
  log.candidates = candidates;
  log.scores = std::move(scores);
  return candidates[argmaxScore(log.scores, candidates)];
}

}  // namespace

int selectRandomView(SelectionStep& step, SelectionLog& log) {
  log.candidates = step.candidates;
  return selectRandom(step.candidates, step.rng);
}

int selectFarthestView(SelectionStep& step, SelectionLog& log) {
  return best(step.candidates, fvsScores(step.scene, step.held, step.candidates, step.options.fvs_metric), log);
}

int selectKmedianView(SelectionStep& step, SelectionLog& log) {
  return best(step.candidates,
              kmedianGains(step.scene, step.held, step.candidates, step.scene.train, poseAngleScale(step.scene)), log);
}

int selectOracleView(SelectionStep& step, SelectionLog& log) {
  // Told the test poses: the k-median gain over them (over the train views where the
  // dataset has no test split, as the evaluation does).
  const Scene& s = step.scene;
  return best(step.candidates,
              kmedianGains(s, step.held, step.candidates, s.test.empty() ? s.train : s.test, poseAngleScale(s)), log);
}

int selectPathVarianceView(SelectionStep& step, SelectionLog& log) {
  const auto t0 = Clock::now();
  std::vector<double> scores =
      pathVarianceScores(step.trainer.gaussians(), step.trainer.rasterSettings(), step.scene, step.held,
                         step.candidates, {step.options.fisher_lambda, step.options.path_variance_kappa},
                         [&step](int done, int total) { step.report(ActivePhase::kFisher, done, total); });
  log.seconds.fisher += secondsSince(t0);
  return best(step.candidates, std::move(scores), log);
}

int selectCoverageView(SelectionStep& step, SelectionLog& log) { return best(step.candidates, step.coverage, log); }

int selectFisherView(SelectionStep& step, SelectionLog& log) {
  const ActiveOptions& o = step.options;
  const std::vector<int>& pool = step.pool;
  const RasterSettings s = step.trainer.rasterSettings();
  auto t0 = Clock::now();
  log.candidates = pool;
  const FisherCriterion criterion = o.method == Method::kFisherLogDet ? FisherCriterion::kLogDet
                                    : o.method == Method::kHybrid     ? o.hybrid_criterion
                                                                      : FisherCriterion::kTrace;
  log.scores = fisherScores(
      step.trainer.gaussians(), s, step.scene, step.held, pool, o.fisher_lambda,
      [&step](int done, int total) { step.report(ActivePhase::kFisher, done, total); }, criterion);
  log.seconds.fisher += secondsSince(t0);
  if (o.method == Method::kFisherKmedian) {
    // Fisher scored every candidate; the k-median gain over them, each weighted by its score
    // (held views are at distance 0 from a held view: they add nothing).
    t0 = Clock::now();
    log.fisher_scores = log.scores;
    log.scores = kmedianGains(step.scene, step.held, pool, pool, poseAngleScale(step.scene), log.fisher_scores);
    log.seconds.prefilter += secondsSince(t0);
  }
  const MethodNeeds needs = needsOf(o.method);
  if (needs.surface) {
    // What the held views see is known from the poses: observing all of them again is a
    // union (cached sets), so a resumed run needs no saved state.
    t0 = Clock::now();
    log.fisher_scores = log.scores;
    if (step.surface) {
      step.surface->observe(step.held);
      log.new_surface = o.hybrid_coverage == HybridCoverage::kFacility
                            ? step.surface->facilityGain(pool, step.scene.train)
                            : step.surface->newSurface(pool);
    } else {
      log.view_distance =
          farthestViewScores(step.scene, step.held, pool, ViewDistance::kEuclidean, Eigen::Vector3d::Zero());
    }
    log.scores = hybridScores(log.fisher_scores, step.surface ? log.new_surface : log.view_distance, o.hybrid_weight);
    log.seconds.coverage += secondsSince(t0);
  }
  if (needs.coverage && o.time_exhaustive_fisher) {
    t0 = Clock::now();
    (void)fisherScores(step.trainer.gaussians(), s, step.scene, step.held, step.candidates, o.fisher_lambda,
                       [&step](int done, int total) { step.report(ActivePhase::kExhaustiveFisher, done, total); });
    log.seconds.exhaustive_fisher += secondsSince(t0);
  }
  return pool[argmaxScore(log.scores, pool)];
}

int selectGatedFisherView(SelectionStep& step, SelectionLog& log) {
  // The gate: a spread score over all candidates, whose top fraction Fisher ranks.
  const auto t0 = Clock::now();
  const Scene& s = step.scene;
  const std::vector<double> gate = usesKmedianGate(s, step.options)
                                       ? kmedianGains(s, step.held, step.candidates, s.train, poseAngleScale(s))
                                       : fvsScores(s, step.held, step.candidates, step.options.fvs_metric);
  step.pool = topFraction(gate, step.candidates, step.options.gate_keep);
  log.prefiltered = step.pool;
  log.seconds.prefilter += secondsSince(t0);
  return selectFisherView(step, log);
}

int selectCustomView(SelectionStep& step, SelectionLog& log) {
  const ActiveOptions& o = step.options;
  const int v = o.custom_selector(
      SelectionContext{step.scene, step.trainer, step.held, step.candidates, step.rng, o.fisher_lambda}, log);
  if (std::find(step.candidates.begin(), step.candidates.end(), v) == step.candidates.end())
    throw std::invalid_argument("custom selector: it chose view " + std::to_string(v) +
                                ", which is not a candidate (a train view not held)");
  if (!log.scores.empty() && log.scores.size() != step.candidates.size())
    throw std::invalid_argument("custom selector: " + std::to_string(log.scores.size()) + " scores for " +
                                std::to_string(step.candidates.size()) + " candidates");
  log.candidates = step.candidates;
  return v;
}

}  // namespace saresgs
