#pragma once
// What an active run is asked to do (ActiveOptions, built from the settings table in
// nbv/active_settings.h) and what its selectors see (SelectionContext), apart from the
// loop itself (nbv/active_run.h), so that the selectors (nbv/selection_step.h) depend on
// the options and not on the loop that calls them.
#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include "geometry/scene/scene.h"
#include "nbv/coverage_prefilter.h"
#include "nbv/method.h"
#include "nbv/selection_log.h"
#include "nbv/selectors.h"
#include "nbv/surface_coverage.h"
#include "splat/train/trainer.h"

namespace saresgs {

// What a caller's selector (ActiveOptions::custom_selector; the Python module's) sees when
// the loop asks it for the next view: the model trained on the held views, the
// candidates (train views not held) and the run's random generator (the one `random`
// draws from, so a caller's random selector can reproduce it). Valid during the call only.
struct SelectionContext {
  const Scene& scene;
  const Trainer& trainer;
  const std::vector<int>& held;
  const std::vector<int>& candidates;
  std::mt19937_64& rng;
  double fisher_lambda = 1e-6;
};
// Returns the chosen candidate; may fill log.scores (one per candidate) for results.json.
using CustomSelector = std::function<int(const SelectionContext&, SelectionLog& log)>;

struct ActiveOptions {
  Method method = Method::kSaResgs;
  int initial_views = 4;
  int max_views = 20;
  int interval = 100;  // iterations per view held
  // The loop's least total: the last phase trains what is left of it and never less than
  // its views x interval, so a run trains max(total_iterations, the phases' sum)
  // (`--min-iterations`; ActiveResult::iterations says what ran).
  int total_iterations = 20000;
  bool reset_after_add = true;
  // After each reset the SH degree restarts at 0 and rises on the run's global iteration
  // clock (FisherRF's reference), not on the phase's own count.
  bool global_sh_clock = true;
  double fisher_lambda = 1e-6;
  ViewDistance fvs_metric = ViewDistance::kEuclidean;
  PrefilterConfig prefilter;
  // hybrid: the share w of the coverage evidence against Fisher's (hybridScores), the
  // Fisher criterion it combines, the coverage evidence, and its surface grid and rays (its
  // own, so that the prefilter's paper settings do not move it). Defaults chosen on the
  // held-out tuning seed 100 (results/grid_tuning.json), not on the verdict's seeds:
  // facility location at w = 0.5 had the smallest worst-case loss against fisher and fvs.
  double hybrid_weight = 0.5;
  FisherCriterion hybrid_criterion = FisherCriterion::kLogDet;
  HybridCoverage hybrid_coverage = HybridCoverage::kFacility;
  SurfaceCoverageOptions hybrid_surface{
      .grid = {.resolution = 64, .min_points = 2, .upsample = 2}, .stride = 4, .tolerance = 1};
  // The gated selectors (kmedian-fisher, fvs-fisher, adaptive): the fraction of the
  // candidates, best by the gate's spread score, that Fisher ranks (the paper's prefilter
  // keeps its top 20 %; the same cut here).
  double gate_keep = 0.2;
  // path-variance: each parameter group's damping is this times the median of its nonzero
  // held information (PathVarianceOptions::kappa; fisher_lambda is the floor).
  double path_variance_kappa = 0.01;
  // adaptive: a capture whose captureClustering (selectors.h) exceeds this is clustered
  // and gets the k-median gate, any other the farthest-view gate. Set between the
  // statistics of the tuning scenes (results/grid_tuning_scenes.json, scene seed 1): the
  // clustered walk 1.51, the orbit, object and two rooms 0.16, 0.27 and 0.19. 0.7 lies
  // between the largest even one and the clustered one (their geometric mean is 0.64),
  // well away from both.
  double adaptive_clustering = 0.7;
  bool time_exhaustive_fisher = false;  // prefiltered methods: also time Fisher on all
  int progress_test_views = 3;
  // After the last view: a fresh model from the initial state trained on exactly the
  // chosen views for this many iterations (0: none), so that the views can be judged
  // apart from the loop's schedule. It trains with the method's own training (residual
  // supervision for the methods that have it, finalFitOptions); for those methods a
  // second, plain 3DGS fit of the same views (ActiveResult::final_fit_views) judges the
  // selection apart from the training.
  int final_iterations = 0;
  // The plain refit above, for methods whose own training is not plain 3DGS. A verdict
  // needs it; a user who wants the reconstruction only may leave it out (it is as long
  // as the final fit itself).
  bool plain_refit = true;
  // The final fit trains with residual supervision whatever the method (`--final-residual`):
  // a plain-training selector's views with the paper's training, the loop and its
  // selection unchanged; the plain refit above then judges the selection alone.
  bool final_residual = false;
  // Its trainer options: 3DGS's own schedule (a fit of a few thousand iterations on 20
  // views is 3DGS's first iterations, not a quarter-speed loop phase), with the preset's
  // model cap and SH degree; residual supervision and the seed are set by finalFitOptions.
  TrainerOptions final_trainer;
  // Fixed-order replay (the paper's ablation ‡): when not empty, the views to hold, in
  // order (the initial ones first, as many as initial_views): the run trains with its own
  // method's training on this sequence instead of selecting (replaySequence, nbv/run_report.h).
  std::vector<int> replay;
  // Method::kCustom: the caller's selector (required for it, unused otherwise).
  CustomSelector custom_selector;
  TrainerOptions trainer;
  std::uint64_t seed = 0;
};

// What an active run is doing; selection stages report per view or candidate handled.
enum class ActivePhase {
  kTraining,
  kLifting,
  kPrefilter,
  kFisher,
  kExhaustiveFisher,
  kFinalEvaluation,
  kFinalFit,
  kFinalFitViews
};
const char* toString(ActivePhase p);  // "training", "lifting", ...

// The gated selectors' gate (kmedian-fisher, fvs-fisher, adaptive): true when Fisher ranks
// the top of the k-median gains, false for the farthest-view distances. adaptive decides
// from the capture (captureClustering against o.adaptive_clustering); any other method
// throws std::invalid_argument.
bool usesKmedianGate(const Scene& scene, const ActiveOptions& o);

// Whether the final fit trains with residual supervision: the method does, or
// o.final_residual asks for it.
bool finalFitIsResidual(const ActiveOptions& o);

// The trainer options of the final fit: final_trainer with the run's seed and, when
// `method_training` and finalFitIsResidual, the loop's residual options (their alpha, beta
// and ranking; otherwise none). `saresgs train` with these options on the chosen views
// (`--residual` and its options for the method's training) trains the same model.
TrainerOptions finalFitOptions(const ActiveOptions& o, bool method_training = true);

}  // namespace saresgs
