#pragma once
// What a person sets for an active run, as one typed table that both front ends read:
// `saresgs active`'s flags and --help (apps/settings_flags.h), Python's ActiveRun keyword
// arguments, and results.json's "settings". A setting left empty keeps the preset's value;
// activeOptionsFrom is the one place that turns settings into ActiveOptions, so the front
// ends cannot drift apart. What only describes where a run reads and writes (the dataset,
// the output folder, a checkpoint, the background, a replayed run) is not a setting.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "geometry/settings_table.h"
#include "nbv/active_options.h"

namespace saresgs {

struct ActiveSettings {
  std::string preset = "quick";
  std::string method = "adaptive";  // a name of methodNames()
  std::uint64_t seed = 0;
  int threads = 0;  // 0: all cores
  std::optional<int> max_views, interval, min_iterations, final_iterations;
  std::optional<std::uint64_t> max_gaussians;  // the loop's and the final fit's cap
  bool plain_refit = true, final_residual = false;
  std::optional<double> fisher_lambda, gate_keep, path_variance_kappa, adaptive_clustering, hybrid_weight;
  bool continue_training = false;  // keep the model after each added view (no reset)
  std::string fvs_metric = "euclidean";
  std::optional<double> residual_beta;
  std::optional<std::string> residual_ranking;
  bool residual_sub_only = false;
  std::string prefilter_set = "frustum", prefilter_encoding = "hash:auto", prefilter_score = "xor",
              prefilter_lifting = "flow", prefilter_scene = "auto";
  std::optional<double> prefilter_keep;
  std::string hybrid_fisher = "logdet", hybrid_coverage = "facility";
  bool time_exhaustive_fisher = false;
};

using ActiveSettingField = SettingField<ActiveSettings>;

// Every setting, in the order --help lists them.
const std::vector<ActiveSettingField>& activeSettingFields();
inline const ActiveSettingField* findActiveSetting(std::string_view name) {
  return findSetting(activeSettingFields(), name);
}
// Sets one setting from a JSON value (what Python's keywords arrive as): checks its type,
// its range and its choices, and throws InputError naming the setting otherwise.
inline void setActiveSetting(ActiveSettings& s, const ActiveSettingField& f, const nlohmann::json& value,
                             SettingNaming naming) {
  setSetting(s, f, value, naming);
}
// Every setting by name (null where left to the preset).
inline nlohmann::json activeSettingsJson(const ActiveSettings& s) { return settingsJson(s, activeSettingFields()); }

// The preset's options with every setting given applied. Throws std::invalid_argument for
// an unknown preset, InputError (named as `naming` says) for a bad prefilter setting.
// `dataset` is read only for prefilter_scene auto (its manifest's layout).
ActiveOptions activeOptionsFrom(const ActiveSettings& s, const std::string& dataset = {},
                                SettingNaming naming = SettingNaming::kFlag);

}  // namespace saresgs
