#pragma once
// The report of one active run: what `saresgs active` writes as results.json, what the
// ablation reads back, and (its steps) what the run's checkpoint stores. Views are named
// as in the dataset; toJson and runReportFromJson are exact inverses on what they write.
#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "geometry/scene/scene.h"
#include "nbv/active_run.h"
#include "nbv/selection_seconds.h"
#include "nbv/step_report.h"

namespace saresgs {

// The options that shaped the run, as the tables name them.
struct RunOptionsReport {
  // total_iterations: the loop's least total (`--min-iterations`); what ran is
  // RunReport::iterations.
  int interval = 0, total_iterations = 0, max_views = 0;
  std::size_t max_gaussians = 0;
  bool reset_after_add = true, residual = false;
  double residual_alpha = 0, residual_beta = 0;
  std::string residual_ranking;
  bool residual_sub_only = false;
  std::string prefilter_set, prefilter_encoding, prefilter_score;
  double prefilter_keep = 0;
};

struct ViewReport {
  std::string name;
  double psnr = 0, ssim = 0;
};

// A final fit: a fresh model trained on exactly the chosen views, with residual
// supervision or plain 3DGS (`residual`; absent in reports written before it was
// recorded, when every final fit was plain).
struct PathViewReport {
  std::string name;
  double psnr = 0;
};
struct FinalFitReport {
  int iterations = 0;
  bool residual = false;
  double psnr = 0, ssim = 0;
  std::vector<ViewReport> views;
  // PSNR of every view of the dataset (FinalFit::path), as "path": [{"name", "psnr"}];
  // empty in reports written before it was recorded.
  std::vector<PathViewReport> path;
};

struct RunReport {
  std::string dataset, method, preset;
  std::uint64_t seed = 0;
  RunOptionsReport options;
  double psnr = 0, ssim = 0;   // mean over the test views (the paper's in-loop model)
  std::optional<double> ause;  // none without ground-truth depth
  std::vector<std::string> initial_views;
  std::vector<std::string> selected_views;  // the views added after the initial ones
  std::vector<int> selected_view_indices;   // every view held at the end, initial first
  SelectionSeconds seconds;                 // summed over steps
  double end_to_end_seconds = 0;            // this process (a resumed run: since resuming)
  std::size_t gaussians = 0;
  int iterations = 0;  // trained in the loop, every phase: at least options.total_iterations
  // Each phase's iterations, the last one's model evaluated (after a reset it trained only
  // that phase); absent in reports written before it was recorded.
  std::optional<std::vector<int>> phase_iterations;
  int threads = 0;
  std::vector<ViewReport> views;  // per test view
  std::vector<StepReport> steps;
  std::optional<FinalFitReport> final_fit;  // the method's own training; none without a final fit
  // Plain 3DGS on the same views, so that selection is judged apart from training: for a
  // method that trains plainly the same numbers as final_fit. A report written before it
  // was recorded gets final_fit here when that fit was plain.
  std::optional<FinalFitReport> final_fit_views;
  // Coverage methods: the prefilter's grid and hash regime, as toJson(PrefilterRegime)
  // writes it (kept as JSON: the report reads it back as written).
  std::optional<nlohmann::json> prefilter_regime;
  // A fixed-order replay: the results file whose view sequence this run trained on.
  std::string replay_of;
  // The frame the run computed in (scene_frame.h); absent in reports written before it was
  // recorded, which all ran in the identity frame.
  std::optional<SceneFrame> frame;
  // The background the run trained and evaluated against (backgroundJson); absent in
  // reports written before it was recorded.
  std::optional<nlohmann::json> background;
};

// Where and how the run was made, which the loop itself does not know.
struct RunContext {
  std::string dataset, preset;
  std::string replay_of;  // the replayed results file, if any
  std::size_t gaussians = 0;
  int threads = 0;
};

RunReport makeRunReport(const Scene& scene, const ActiveOptions& opt, const ActiveResult& r, const RunContext& c);

nlohmann::json toJson(const RunReport& r);
// Throws InputError naming `source` and the field when a field is missing or mistyped.
RunReport runReportFromJson(const nlohmann::json& j, const std::string& source);

// The views a run held, in order (initial first), as indices into `scene`: what a fixed-order
// replay (ActiveOptions::replay) trains on. InputError names `source` and the field when a
// view is not a train view of `scene`.
std::vector<int> replaySequence(const Scene& scene, const RunReport& r, const std::string& source);

}  // namespace saresgs
