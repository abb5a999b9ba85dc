#pragma once
// Named sizes of an active run. `paper`: the paper's protocol (100 iterations per view
// held, 20 000 in all, 3DGS's schedule). `quick`: the same protocol at a quarter of the
// schedule, for a first result on two cores (preset.cpp says how it was sized).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "nbv/active_run.h"

namespace saresgs {

enum class Preset { kPaper, kQuick };

Preset parsePreset(std::string_view text);  // paper | quick; std::invalid_argument otherwise
const char* toString(Preset p);

// The options of a preset (method, seed and everything a caller overrides left at their
// defaults).
ActiveOptions presetOptions(Preset p);

// What a person sets for an active run, as `saresgs active` and Python's ActiveRun both
// name it; an option left empty keeps the preset's value. The one place that turns them
// into ActiveOptions (activeOptionsFrom), so the two front ends cannot drift apart.
struct ActiveSettings {
  std::string preset = "quick";
  Method method = Method::kAdaptive;
  std::uint64_t seed = 0;
  int threads = 0;  // 0: all cores
  std::optional<int> max_views, interval, min_iterations, final_iterations;
  std::optional<std::size_t> max_gaussians;  // the loop's and the final fit's cap
  bool plain_refit = true, final_residual = false;
  std::optional<double> fisher_lambda, gate_keep, path_variance_kappa, adaptive_clustering, hybrid_weight;
};

// The preset's options with every setting given applied. Throws std::invalid_argument for
// an unknown preset.
ActiveOptions activeOptionsFrom(const ActiveSettings& s);

}  // namespace saresgs
