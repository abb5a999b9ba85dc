// The table of a training's settings (splat/train/train_settings.h): nothing set gives
// TrainerOptions' defaults, every row reads back what it wrote, and the schedule is scaled
// after the rows that it scales.
#include <gtest/gtest.h>

#include <set>

#include "geometry/error.h"
#include "splat/train/schedule.h"
#include "splat/train/train_settings.h"

namespace saresgs {
namespace {

TEST(TrainSettingsTable, NothingSetIsTheTrainersDefaults) {
  const TrainerOptions d, o = trainerOptionsFrom(TrainSettings{});
  EXPECT_EQ(o.seed, d.seed);
  EXPECT_EQ(o.max_sh_degree, d.max_sh_degree);
  EXPECT_EQ(o.densify.until_iter, d.densify.until_iter);
  EXPECT_EQ(o.densify.max_gaussians, d.densify.max_gaussians);
  EXPECT_EQ(o.random_init_points, d.random_init_points);
  EXPECT_EQ(o.residual.enabled, d.residual.enabled);
  EXPECT_EQ(o.residual.alpha, d.residual.alpha);
  EXPECT_EQ(o.residual.beta, d.residual.beta);
  EXPECT_EQ(o.residual.ranking, d.residual.ranking);
  EXPECT_EQ(o.raster.execution.threads, d.raster.execution.threads);
}

TEST(TrainSettingsTable, RowsRoundTripAndTheScheduleScalesLast) {
  std::set<std::string> flags;
  for (const auto& f : trainSettingFields()) EXPECT_TRUE(flags.insert(settingFlag(f)).second) << f.name;
  EXPECT_TRUE(flags.count("--sh-degree"));  // the CLI's historical name for max_sh_degree
  TrainSettings s;
  s.seed = 4;
  s.densify_until = 8000;
  s.residual = true;
  s.residual_ranking = "scale";
  s.schedule_scale = 0.25;
  const nlohmann::json j = trainSettingsJson(s);
  TrainSettings back;
  for (const auto& f : trainSettingFields()) setSetting(back, f, j.at(f.name), SettingNaming::kKeyword);
  EXPECT_EQ(trainSettingsJson(back), j);
  const TrainerOptions o = trainerOptionsFrom(back);
  TrainerOptions want;
  want.seed = 4;
  want.densify.until_iter = 8000;
  want.residual.enabled = true;
  want.residual.ranking = UncertaintyRanking::kScale;
  want = scaledSchedule(want, 0.25);
  EXPECT_EQ(o.densify.until_iter, want.densify.until_iter);
  EXPECT_EQ(o.densify.until_iter, 2000);
  EXPECT_EQ(o.residual.ranking, UncertaintyRanking::kScale);
  EXPECT_THROW(setSetting(back, *findSetting(trainSettingFields(), "max_sh_degree"), 4, SettingNaming::kKeyword),
               InputError);
}

}  // namespace
}  // namespace saresgs
