#pragma once
// What a person sets for one training (`saresgs train`, Python's Trainer), as one typed
// table (geometry/settings_table.h) that makes the CLI's flags and --help, Python's keywords
// and results.json's "settings"; trainerOptionsFrom is the one place that turns them into
// TrainerOptions. What says where it reads and writes (dataset, output, views, checkpoints,
// background, memory budget) is not a setting.
#include <cstdint>
#include <string>
#include <vector>

#include "geometry/settings_table.h"
#include "splat/train/trainer.h"

namespace saresgs {

struct TrainSettings {
  std::uint64_t seed = 0;
  int max_sh_degree = TrainerOptions{}.max_sh_degree;
  int densify_until = TrainerOptions{}.densify.until_iter;
  std::uint64_t max_gaussians = 0;  // 0: none
  int random_init = TrainerOptions{}.random_init_points;
  bool residual = false;
  double schedule_scale = 1.0;
  double residual_alpha = ResidualOptions{}.alpha, residual_beta = ResidualOptions{}.beta;
  std::string residual_ranking = "both";
  int threads = 0;  // 0: every core
};

using TrainSettingField = SettingField<TrainSettings>;

const std::vector<TrainSettingField>& trainSettingFields();
inline nlohmann::json trainSettingsJson(const TrainSettings& s) { return settingsJson(s, trainSettingFields()); }

// TrainerOptions' defaults with every setting applied, the schedule scaled last.
TrainerOptions trainerOptionsFrom(const TrainSettings& s);

}  // namespace saresgs
