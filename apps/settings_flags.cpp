#include "apps/settings_flags.h"

#include <cmath>
#include <type_traits>

#include "apps/cli_checks.h"
#include "nbv/method.h"

namespace saresgs::apps {

namespace {

// The checks of a row on the flag's text, before conversion (so a negative value never
// wraps into an unsigned setting).
void addChecks(CLI::Option* o, const SettingField& f, bool whole) {
  if (!f.choices.empty()) o->check(CLI::IsMember(f.choices));
  if (f.positive) o->check(positiveNumber());
  if (std::isinf(f.hi) && std::isfinite(f.lo) && whole)
    o->check(wholeNumberAtLeast(static_cast<long long>(f.lo)));
  else if (std::isfinite(f.lo) || std::isfinite(f.hi))
    o->check(CLI::Range(f.lo, f.hi));
  if (f.show_default) o->capture_default_str();
}

}  // namespace

void addSettingFlags(CLI::App* sub, ActiveSettings& settings) {
  for (const SettingField& f : activeSettingFields()) {
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
          } else if constexpr (std::is_same_v<T, Method>) {
            CLI::Option* o = sub->add_option_function<std::string>(
                flag, [&value](const std::string& name) { value = parseMethod(name); }, f.help);
            o->default_str(toString(value));
            addChecks(o, f, false);
          } else {
            constexpr bool whole = !std::is_same_v<T, std::optional<double>> && !std::is_same_v<T, double> &&
                                   !std::is_same_v<T, std::string> && !std::is_same_v<T, std::optional<std::string>>;
            addChecks(sub->add_option(flag, value, f.help), f, whole);
          }
        },
        f.member);
  }
}

}  // namespace saresgs::apps
