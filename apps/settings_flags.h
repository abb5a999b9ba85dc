#pragma once
// A command's flags for every row of a settings table (geometry/settings_table.h): the
// flag, its help and its checks come from the row, the value lands in `settings`.
#include <CLI/CLI.hpp>

#include <cmath>
#include <type_traits>

#include "apps/cli_checks.h"
#include "geometry/settings_table.h"

namespace saresgs::apps {

// The row's checks on the flag's text, before conversion (so a negative value never wraps
// into an unsigned setting).
inline void addSettingChecks(CLI::Option* o, const SettingRule& r, bool whole, bool show_default) {
  if (!r.choices.empty()) o->check(CLI::IsMember(r.choices));
  if (r.positive) o->check(positiveNumber());
  if (std::isinf(r.hi) && std::isfinite(r.lo) && whole)
    o->check(wholeNumberAtLeast(static_cast<long long>(r.lo)));
  else if (whole && std::isfinite(r.lo) && std::isfinite(r.hi))
    o->check(CLI::Range(static_cast<long long>(r.lo), static_cast<long long>(r.hi)));
  else if (std::isfinite(r.lo) || std::isfinite(r.hi))
    o->check(CLI::Range(r.lo, r.hi));
  if (show_default) o->capture_default_str();
}

template <typename S>
void addSettingFlags(CLI::App* sub, S& settings, const std::vector<SettingField<S>>& table) {
  for (const SettingField<S>& f : table) {
    const std::string flag = settingFlag(f);
    std::visit(
        [&](auto member) {
          auto& value = settings.*member;
          using T = std::remove_reference_t<decltype(value)>;
          if constexpr (std::is_same_v<T, bool>) {
            if (flag.rfind("--no-", 0) == 0)
              sub->add_flag_callback(
                  flag, [&value] { value = false; }, f.help);
            else
              sub->add_flag(flag, value, f.help);
          } else {
            constexpr bool whole = !std::is_same_v<T, std::optional<double>> && !std::is_same_v<T, double> &&
                                   !std::is_same_v<T, std::string> && !std::is_same_v<T, std::optional<std::string>>;
            addSettingChecks(sub->add_option(flag, value, f.help), f, whole, f.show_default);
          }
        },
        f.member);
  }
}

}  // namespace saresgs::apps
