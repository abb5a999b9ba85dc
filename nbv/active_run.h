#pragma once
// The active reconstruction loop (the protocol in docs/DESIGN.md): start from train index 0 plus 3
// views by farthest-point sampling; with k views train k x interval iterations, then
// select one more view among the remaining train views, until max_views; then train the
// rest of the iteration budget and evaluate. After each addition the model restarts from
// its initial state (an option continues instead). A checkpoint after every added view
// lets a killed run resume and end with the same numbers.
#include <nlohmann/json.hpp>

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "geometry/scene/scene.h"
#include "nbv/coverage_prefilter.h"
#include "nbv/method.h"
#include "nbv/selection_log.h"
#include "nbv/selection_seconds.h"
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

struct ActiveProgress {
  ActivePhase phase = ActivePhase::kTraining;
  int phase_done = 0, phase_total = 0;  // within the phase: iterations, views or candidates
  int views = 0, max_views = 0;
  int iteration = 0, total_iterations = 0;  // over the whole run
  double loss = 0, psnr = 0;                // latest loss; PSNR after the last phase
  std::size_t gaussians = 0;
};

// The final fit's outcome (ActiveOptions::final_iterations).
struct FinalFit {
  int iterations = 0;
  bool residual = false;  // trained with residual supervision
  Evaluation test;
  // PSNR (no SSIM) of every view of the dataset, train and test, held or not: the whole
  // path a person may look along.
  std::vector<ViewMetrics> path;
};

struct ActiveResult {
  std::vector<int> initial_views, selected_views;
  std::vector<SelectionLog> steps;
  Evaluation test;
  std::optional<double> ause;
  std::optional<PrefilterRegime> prefilter;  // coverage methods: the prefilter's grid and hash
  std::optional<FinalFit> final_fit;         // the method's own training on the chosen views
  std::optional<FinalFit> final_fit_views;   // plain 3DGS on the same views (a copy of
                                             // final_fit when the method trains plainly)
  SelectionSeconds total_seconds;
  int iterations = 0;                 // training iterations over the whole run
  std::vector<int> phase_iterations;  // per phase: k x interval for k views held, then the last
  double seconds = 0;                 // end to end, this process
};

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

class ActiveRun {
 public:
  // `checkpoint` names the checkpoint file (empty: none). A present checkpoint is resumed.
  ActiveRun(const Scene& scene, const ActiveOptions& opt, std::string checkpoint = {});
  // The whole loop: begin(), then per phase trainPhase(), nextView() and addView() until
  // the last phase is trained, then finish().
  ActiveResult run(const std::function<void(const ActiveProgress&)>& progress = {});

  // The same loop one piece at a time (what the Python module's ActiveRun steps through);
  // run() is exactly these calls. begin() resumes the checkpoint or holds the initial
  // views (the other calls begin when needed).
  void begin();
  void setProgress(std::function<void(const ActiveProgress&)> progress) { progress_ = std::move(progress); }
  const std::vector<int>& held() const { return selected_; }
  // True once the last phase (max_views held, or every train view) has been trained.
  bool finished() const { return finished_; }
  // Trains the phase of the views held now; nothing when it is trained already.
  void trainPhase();
  // The method's choice after the current phase (trained first when needed), computed once
  // per phase; `log` receives the selection's record. Throws std::logic_error when the run
  // holds its last view.
  int nextView(SelectionLog* log = nullptr);
  // Holds train view v next (the method's choice or any other train view not held),
  // records the selection and writes the checkpoint. Throws std::invalid_argument for a
  // view that is not a train view or is held, std::logic_error after the last phase.
  void addView(int v);
  // The final evaluation and final fit; throws std::logic_error before the last phase
  // was trained (trainPhase() trains it once the run holds its last view).
  ActiveResult finish();

  const Trainer& trainer() const { return *trainer_; }
  // The final fit's model (null before run() or without a final fit).
  const Trainer* finalFitTrainer() const { return final_fit_.get(); }
  // The plain refit's model, when it differs from the final fit (residual methods).
  const Trainer* finalFitViewsTrainer() const { return final_fit_views_.get(); }

 private:
  int selectNext(SelectionLog& log);
  bool lastPhase() const;
  void checkReplay() const;
  // Passes the latest state, in `phase` at done/total, to the caller's progress callback.
  void report(ActivePhase phase, int done, int total);
  void saveCheckpoint() const;
  bool loadCheckpoint();
  void checkLoadedState() const;

  Scene scene_;
  ActiveOptions opt_;
  std::string checkpoint_;
  std::unique_ptr<Trainer> trainer_;
  std::unique_ptr<CoveragePrefilter> prefilter_;
  std::unique_ptr<SurfaceCoverage> surface_;
  std::unique_ptr<Trainer> final_fit_, final_fit_views_;
  std::mt19937_64 rng_;
  std::vector<int> initial_, selected_;
  std::vector<SelectionLog> steps_;
  int iterations_done_ = 0;
  int observed_upto_ = 0;                                // selected_[0..observed_upto_) are in the prefilter's grids
  std::function<void(const ActiveProgress&)> progress_;  // during run()
  ActiveProgress last_;                                  // what was last reported
  // Stepping state: begun, the current phase trained (and its seconds), the last phase
  // trained, the selection computed for the current phase.
  bool begun_ = false, phase_trained_ = false, finished_ = false;
  double phase_seconds_ = 0, last_psnr_ = 0;
  std::vector<int> progress_views_;
  std::optional<SelectionLog> pending_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace saresgs
