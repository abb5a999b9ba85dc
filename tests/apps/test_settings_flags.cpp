// `saresgs active`'s flags come from the settings table (apps/settings_flags.h): every row
// is a flag of the real program, takes a value the table allows, and refuses one it does
// not, with the flag's name.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <string>

#include "common/run_command.h"
#include "nbv/active_settings.h"

namespace saresgs::apps {
namespace {

// `saresgs active` on a dataset that does not exist: a parse error, or the dataset's error
// once every flag has parsed.
saresgs::test::CommandResult activeWith(const std::string& flags) {
  return saresgs::test::runCommand(std::string(SARESGS_CLI) + " active --dataset /nonexistent/dataset --out " +
                                   "/nonexistent/out " + flags);
}

// A value the row accepts, as flag text; empty for a switch.
std::string goodValue(const ActiveSettingField& f) {
  if (!f.choices.empty()) return f.choices.back();
  if (std::holds_alternative<bool ActiveSettings::*>(f.member)) return "";
  if (std::holds_alternative<std::string ActiveSettings::*>(f.member)) {
    const nlohmann::json d = activeSettingsJson(ActiveSettings{}).at(f.name);
    return d.get<std::string>();
  }
  if (f.positive) return "0.5";
  if (std::isfinite(f.hi)) return f.hi >= 1 ? "1" : "0.5";
  return std::to_string(static_cast<long long>(std::isfinite(f.lo) ? f.lo : 0) + 1);
}

TEST(SettingsFlags, EveryRowIsAFlagThatTakesWhatTheRowAllows) {
  for (const auto& f : activeSettingFields()) {
    const std::string v = goodValue(f);
    const auto r = activeWith(settingFlag(f) + (v.empty() ? "" : " '" + v + "'"));
    EXPECT_EQ(r.code, 1) << settingFlag(f) << " " << v << ": " << r.output;
    EXPECT_NE(r.output.find("/nonexistent/dataset: dataset: folder does not exist"), std::string::npos)
        << settingFlag(f) << " " << v << ": " << r.output;
  }
}

TEST(SettingsFlags, AValueOutsideTheRowIsRefusedNamingTheFlag) {
  for (const auto& [flag, value] : std::vector<std::pair<std::string, std::string>>{{"--max-views", "0"},
                                                                                    {"--gate-keep", "1.5"},
                                                                                    {"--fvs-metric", "manhattan"},
                                                                                    {"--threads", "-1"},
                                                                                    {"--seed", "-3"},
                                                                                    {"--method", "best"},
                                                                                    {"--fisher-lambda", "0"}}) {
    const auto r = activeWith(flag + " " + value);
    EXPECT_NE(r.code, 0) << flag << " " << value;
    EXPECT_NE(r.output.find(flag), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("folder does not exist"), std::string::npos) << flag << " " << value << ": " << r.output;
  }
}

}  // namespace
}  // namespace saresgs::apps
