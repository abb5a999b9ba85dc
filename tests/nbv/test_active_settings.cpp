// The table of an active run's settings (nbv/active_settings.h): every row reads back what
// it wrote, rejects what it should, and names itself as each front end does.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <set>

#include "geometry/error.h"
#include "nbv/active_settings.h"
#include "nbv/preset.h"

namespace saresgs {
namespace {

TEST(ActiveSettingsTable, NamesAndFlagsAreDistinctAndFollowOneRule) {
  std::set<std::string> names, flags;
  for (const auto& f : activeSettingFields()) {
    EXPECT_TRUE(names.insert(f.name).second) << f.name;
    EXPECT_TRUE(flags.insert(settingFlag(f)).second) << settingFlag(f);
    EXPECT_FALSE(f.help.empty()) << f.name;
    EXPECT_EQ(findActiveSetting(f.name), &f);
  }
  EXPECT_EQ(settingFlag(*findActiveSetting("max_views")), "--max-views");
  // A switch that is on by default is turned off by its flag.
  EXPECT_EQ(settingFlag(*findActiveSetting("plain_refit")), "--no-plain-refit");
  EXPECT_EQ(settingLabel(*findActiveSetting("gate_keep"), SettingNaming::kKeyword), "gate_keep");
  EXPECT_EQ(findActiveSetting("no_such_setting"), nullptr);
}

TEST(ActiveSettingsTable, JsonRoundTripsEveryRow) {
  ActiveSettings s;
  s.method = "fisher";
  s.seed = 9;
  s.max_views = 12;
  s.max_gaussians = 5000;
  s.plain_refit = false;
  s.gate_keep = 0.3;
  s.residual_ranking = "scale";
  s.prefilter_scene = "indoor";
  s.continue_training = true;
  const nlohmann::json j = activeSettingsJson(s);
  ASSERT_EQ(j.size(), activeSettingFields().size());
  EXPECT_EQ(j.at("method"), "fisher");
  EXPECT_TRUE(j.at("interval").is_null());  // left to the preset
  ActiveSettings back;
  for (const auto& f : activeSettingFields()) setActiveSetting(back, f, j.at(f.name), SettingNaming::kKeyword);
  EXPECT_EQ(activeSettingsJson(back), j);
  // And the options they make are the same.
  const ActiveOptions a = activeOptionsFrom(s), b = activeOptionsFrom(back);
  EXPECT_EQ(a.method, b.method);
  EXPECT_EQ(a.max_views, b.max_views);
  EXPECT_EQ(a.trainer.densify.max_gaussians, 5000u);
  EXPECT_FALSE(b.reset_after_add);
  EXPECT_EQ(b.trainer.residual.ranking, UncertaintyRanking::kScale);
}

// What a keyword may not be: the error names the setting as the front end does.
void expectRejected(const char* name, const nlohmann::json& v, const std::string& says) {
  ActiveSettings s;
  try {
    setActiveSetting(s, *findActiveSetting(name), v, SettingNaming::kKeyword);
    ADD_FAILURE() << name << " = " << v.dump() << " was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), name);
    EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
  }
}

TEST(ActiveSettingsTable, RejectsValuesOutsideTheRowWithTheSettingsName) {
  expectRejected("max_views", 0, ">= 1");
  expectRejected("max_views", 2.5, "whole number");
  expectRejected("max_views", "ten", "whole number");
  expectRejected("gate_keep", 1.5, "[0, 1]");
  expectRejected("fisher_lambda", 0.0, "> 0");
  expectRejected("threads", 2048, "[0, 1024]");
  expectRejected("seed", -1, ">= 0");
  expectRejected("fvs_metric", "manhattan", "euclidean | great-circle");
  expectRejected("method", "best", "random");
  expectRejected("plain_refit", 1, "true or false");
  expectRejected("gate_keep", std::nan(""), "finite");
  // null empties what may be empty.
  ActiveSettings s;
  s.max_views = 4;
  setActiveSetting(s, *findActiveSetting("max_views"), nullptr, SettingNaming::kKeyword);
  EXPECT_FALSE(s.max_views.has_value());
}

TEST(ActiveSettingsTable, ABadPrefilterValueNamesTheFrontEndsSpelling) {
  ActiveSettings s;
  s.prefilter_set = "sphere";
  try {
    (void)activeOptionsFrom(s, {}, SettingNaming::kKeyword);
    ADD_FAILURE() << "prefilter_set sphere accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("prefilter_set"), std::string::npos) << e.what();
  }
  try {
    (void)activeOptionsFrom(s, {}, SettingNaming::kFlag);
    ADD_FAILURE() << "--prefilter-set sphere accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--prefilter-set"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace saresgs
