#pragma once
// `saresgs bench select`: one selection step of FisherRF and of path-variance on the same
// model, held views and candidates, alternated round by round so that the machine's drift
// hits both alike. The model is the quick preset's, trained on the held views (farthest
// point sampling of the train cameras, as an active run's first views) for a few hundred
// iterations, so that its Gaussians and their footprints are a run's, not a random cloud's.
#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "geometry/scene/scene.h"

namespace saresgs {

struct SelectionBenchOptions {
  int held = 10;               // views held when the step is taken
  int train_iterations = 300;  // training of the model on them first
  int rounds = 5;              // each round times one step of each method
  std::uint64_t seed = 0;
  int threads = 0;      // 0: every core
  double kappa = 0.01;  // path-variance's relative damping
};

struct SelectionBenchResult {
  int candidates = 0;
  std::size_t gaussians = 0;
  std::vector<double> fisher_seconds, path_variance_seconds;  // one per round
  // The two methods' choices (the same every round: the steps are deterministic).
  int fisher_choice = -1, path_variance_choice = -1;
  // FisherRF's damping examined (unseenShare): per candidate, the share of its trace score
  // that comes from parameters no held view has really seen (held information below 1e-3
  // of its group's median), at FisherRF's lambda; untimed.
  std::vector<double> unseen_share;
  double fisher_choice_unseen_share = 0;
};

SelectionBenchResult benchSelection(const Scene& scene, const SelectionBenchOptions& opt);

// benchSelection on the dataset at `path` as one JSON line: each round's seconds and
// their ratio (path-variance / FisherRF), the medians, both choices, FisherRF's unseen
// share, with the machine and its load named. Caps TBB at opt.threads while it runs.
nlohmann::json benchSelectionJson(const std::string& path, const SelectionBenchOptions& opt);

}  // namespace saresgs
