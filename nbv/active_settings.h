#pragma once
// What a person sets for an active run, as one typed table that both front ends read:
// `saresgs active`'s flags and --help (apps/settings_flags.h), Python's ActiveRun keyword
// arguments, and results.json's "settings". A setting left empty keeps the preset's value;
// activeOptionsFrom is the one place that turns settings into ActiveOptions, so the front
// ends cannot drift apart. What only describes where a run reads and writes (the dataset,
// the output folder, a checkpoint, the background, a replayed run) is not a setting.
#include <nlohmann/json_fwd.hpp>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "nbv/active_run.h"

namespace saresgs {

struct ActiveSettings {
  std::string preset = "quick";
  Method method = Method::kAdaptive;
  std::uint64_t seed = 0;
  int threads = 0;  // 0: all cores
  std::optional<int> max_views, interval, min_iterations, final_iterations;
  std::optional<std::size_t> max_gaussians;  // the loop's and the final fit's cap
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

// How a front end names a setting in its messages: `--max-views` or `max_views`.
enum class SettingNaming { kFlag, kKeyword };

using SettingMember =
    std::variant<std::string ActiveSettings::*, Method ActiveSettings::*, std::uint64_t ActiveSettings::*,
                 int ActiveSettings::*, bool ActiveSettings::*, std::optional<int> ActiveSettings::*,
                 std::optional<std::size_t> ActiveSettings::*, std::optional<double> ActiveSettings::*,
                 std::optional<std::string> ActiveSettings::*>;

// One row of the table.
struct SettingField {
  std::string name;  // snake_case: the Python keyword and the results.json key
  std::string help;
  SettingMember member;
  // Numbers: the closed range accepted (whole numbers for the integer members); `positive`
  // asks > 0 instead of a lower bound.
  double lo = -std::numeric_limits<double>::infinity(), hi = std::numeric_limits<double>::infinity();
  bool positive = false;
  std::vector<std::string> choices;  // text: the values accepted (empty: any; the options' parser checks)
  bool show_default = false;         // --help shows the default (the others say "preset's" in their help)
};

// Every setting, in the order --help lists them.
const std::vector<SettingField>& activeSettingFields();
const SettingField* findActiveSetting(std::string_view name);
// `--max-views` for `max_views`; `--no-plain-refit` for a switch that is on by default.
std::string settingFlag(const SettingField& f);
std::string settingLabel(const SettingField& f, SettingNaming naming);

// Sets one field from a JSON value (what Python's keywords arrive as): checks its type, its
// range and its choices, and throws InputError naming the setting otherwise. null empties
// an optional setting.
void setActiveSetting(ActiveSettings& s, const SettingField& f, const nlohmann::json& value, SettingNaming naming);
// Every setting by name (null where left to the preset).
nlohmann::json activeSettingsJson(const ActiveSettings& s);

// The preset's options with every setting given applied. Throws std::invalid_argument for
// an unknown preset, InputError (named as `naming` says) for a bad prefilter setting.
// `dataset` is read only for prefilter_scene auto (its manifest's layout).
ActiveOptions activeOptionsFrom(const ActiveSettings& s, const std::string& dataset = {},
                                SettingNaming naming = SettingNaming::kFlag);

}  // namespace saresgs
