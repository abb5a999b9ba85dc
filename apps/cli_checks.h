#pragma once
// Option checks with messages a user can read (CLI11's own NonNegativeNumber prints the
// largest double as the upper bound). Each runs on the text, before the conversion, so a
// negative value never wraps into an unsigned option.
#include <CLI/CLI.hpp>

#include <cmath>
#include <string>

#include "geometry/scene/background.h"

namespace saresgs::apps {

// An option within [lo, hi], its default shown in --help: the form most flags take.
template <typename T, typename B>
CLI::Option* addRanged(CLI::App* sub, const std::string& name, T& value, const std::string& help, B lo, B hi) {
  return sub->add_option(name, value, help)->check(CLI::Range(lo, hi))->capture_default_str();
}

// A whole number >= `min` (seeds, counts, caps).
inline CLI::Validator wholeNumberAtLeast(long long min) {
  return CLI::Validator(
      [min](std::string& s) -> std::string {
        std::size_t used = 0;
        long long v = 0;
        try {
          v = std::stoll(s, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used != s.size() || s.empty() || v < min)
          return "'" + s + "': expected a whole number >= " + std::to_string(min);
        return {};
      },
      "INT>=" + std::to_string(min));
}

// A finite number > 0.
inline CLI::Validator positiveNumber() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        std::size_t used = 0;
        double v = 0;
        try {
          v = std::stod(s, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used != s.size() || s.empty() || !std::isfinite(v) || !(v > 0)) return "'" + s + "': expected a number > 0";
        return {};
      },
      "NUMBER>0");
}

// A background: white, black, random or R,G,B (geometry/scene/background.h).
inline CLI::Validator backgroundValue() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        try {
          parseBackground(s, "--background");
        } catch (const std::exception&) {
          return "'" + s + "': expected " + std::string(kBackgroundForms);
        }
        return {};
      },
      "white|black|R,G,B|random");
}

// --background's help, the same for every command that takes it.
inline constexpr const char* kBackgroundHelp =
    "What stands behind the content: RGBA images are composited on it and every render is against it; random: a "
    "fresh colour per training step, evaluated on white (default: what the data says: a saresgs scene manifest, "
    "Blender's white, white for images with alpha; else none)";

}  // namespace saresgs::apps
