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
#include "nbv/active_options.h"
#include "nbv/coverage_prefilter.h"
#include "nbv/method.h"
#include "nbv/selection_log.h"
#include "nbv/selection_seconds.h"
#include "nbv/selectors.h"
#include "nbv/surface_coverage.h"
#include "splat/train/trainer.h"

namespace saresgs {

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
