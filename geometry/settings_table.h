#pragma once
// A typed table of a command's settings, read alike by every front end: each row names a
// member of a settings struct S, its help, the values it accepts and its flag. The CLI
// makes its flags and --help from it (apps/settings_flags.h), Python takes its keywords
// through setSetting, and a run's results.json records settingsJson. Tables:
// nbv/active_settings.h (saresgs active, ActiveRun), splat/train/train_settings.h
// (saresgs train, Trainer).
#include <nlohmann/json.hpp>

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

#include "geometry/error.h"

namespace saresgs {

// How a front end names a setting in its messages: `--max-views` or `max_views`.
enum class SettingNaming { kFlag, kKeyword };

// What a row accepts. Numbers: the closed range (whole numbers for integer members), or
// > 0 with `positive`. Text: one of `choices` (empty: any; the options' parser checks).
struct SettingRule {
  double lo = -std::numeric_limits<double>::infinity(), hi = std::numeric_limits<double>::infinity();
  bool positive = false;
  std::vector<std::string> choices;
};

template <typename S>
using SettingMember =
    std::variant<std::string S::*, std::uint64_t S::*, int S::*, bool S::*, double S::*, std::optional<int> S::*,
                 std::optional<std::uint64_t> S::*, std::optional<double> S::*, std::optional<std::string> S::*>;

template <typename S>
struct SettingField : SettingRule {
  std::string name;  // snake_case: the Python keyword and the results.json key
  std::string help;
  SettingMember<S> member;
  std::string flag;           // empty: `--` + name with dashes (`--no-` for a switch on by default)
  bool show_default = false;  // --help shows the default (the others say it in their help)
};

// Appends the row (name, member, help) to `table`; the caller sets its rule and flag on
// the returned row before the next row is added.
template <typename S>
SettingField<S>& addSetting(std::vector<SettingField<S>>& table, std::string name, SettingMember<S> member,
                            std::string help) {
  SettingField<S>& r = table.emplace_back();
  r.name = std::move(name);
  r.member = member;
  r.help = std::move(help);
  return r;
}

// The checks of one value (what setSetting applies); InputError naming `label` otherwise.
double checkedSettingNumber(const SettingRule& r, const nlohmann::json& v, bool whole, const std::string& label);
std::string checkedSettingText(const SettingRule& r, const nlohmann::json& v, const std::string& label);

template <typename S>
std::string settingFlag(const SettingField<S>& f) {
  if (!f.flag.empty()) return f.flag;
  std::string flag = f.name;
  for (char& c : flag)
    if (c == '_') c = '-';
  const auto* b = std::get_if<bool S::*>(&f.member);
  const bool on_by_default = b && S{}.**b;
  return (on_by_default ? "--no-" : "--") + flag;
}

template <typename S>
std::string settingLabel(const SettingField<S>& f, SettingNaming naming) {
  return naming == SettingNaming::kFlag ? settingFlag(f) : f.name;
}

template <typename S>
const SettingField<S>* findSetting(const std::vector<SettingField<S>>& table, std::string_view name) {
  for (const SettingField<S>& f : table)
    if (f.name == name) return &f;
  return nullptr;
}

// Sets one member from a JSON value (what Python's keywords arrive as), checked by its
// row; null empties an optional member.
template <typename S>
void setSetting(S& s, const SettingField<S>& f, const nlohmann::json& v, SettingNaming naming) {
  const std::string label = settingLabel(f, naming);
  std::visit(
      [&](auto member) {
        using T = std::remove_reference_t<decltype(s.*member)>;
        if constexpr (std::is_same_v<T, bool>) {
          if (!v.is_boolean()) throw InputError(label, "value", "expected true or false, got " + v.dump());
          s.*member = v.get<bool>();
        } else if constexpr (std::is_same_v<T, std::string>) {
          s.*member = checkedSettingText(f, v, label);
        } else if constexpr (std::is_same_v<T, double>) {
          s.*member = checkedSettingNumber(f, v, false, label);
        } else if constexpr (std::is_same_v<T, int> || std::is_same_v<T, std::uint64_t>) {
          s.*member = static_cast<T>(checkedSettingNumber(f, v, true, label));
        } else if (v.is_null()) {
          s.*member = std::nullopt;
        } else if constexpr (std::is_same_v<T, std::optional<std::string>>) {
          s.*member = checkedSettingText(f, v, label);
        } else if constexpr (std::is_same_v<T, std::optional<double>>) {
          s.*member = checkedSettingNumber(f, v, false, label);
        } else {
          s.*member = static_cast<typename T::value_type>(checkedSettingNumber(f, v, true, label));
        }
      },
      f.member);
}

// Every row's value by name (null where an optional member is empty).
template <typename S>
nlohmann::json settingsJson(const S& s, const std::vector<SettingField<S>>& table) {
  nlohmann::json j = nlohmann::json::object();
  for (const SettingField<S>& f : table)
    std::visit(
        [&](auto member) {
          const auto& value = s.*member;
          if constexpr (requires { value.has_value(); })
            j[f.name] = value ? nlohmann::json(*value) : nlohmann::json(nullptr);
          else
            j[f.name] = value;
        },
        f.member);
  return j;
}

}  // namespace saresgs
