#include "geometry/settings_table.h"

#include <cmath>
#include <sstream>

namespace saresgs {

namespace {

std::string numberText(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

}  // namespace

double checkedSettingNumber(const SettingRule& r, const nlohmann::json& v, bool whole, const std::string& label) {
  if (!v.is_number() || (whole && !v.is_number_integer()))
    throw InputError(label, "value",
                     std::string("expected ") + (whole ? "a whole number" : "a number") + ", got " + v.dump());
  const double x = v.get<double>();
  if (!std::isfinite(x)) throw InputError(label, "value", "expected a finite number, got " + v.dump());
  if (r.positive && !(x > 0)) throw InputError(label, "value", "expected a number > 0, got " + v.dump());
  if (x < r.lo || x > r.hi)
    throw InputError(label, "value",
                     "expected " +
                         (std::isinf(r.hi) ? ">= " + numberText(r.lo)
                                           : "a value in [" + numberText(r.lo) + ", " + numberText(r.hi) + "]") +
                         ", got " + v.dump());
  return x;
}

std::string checkedSettingText(const SettingRule& r, const nlohmann::json& v, const std::string& label) {
  if (!v.is_string()) throw InputError(label, "value", "expected text, got " + v.dump());
  const std::string t = v.get<std::string>();
  if (r.choices.empty()) return t;
  std::string list;
  for (const std::string& c : r.choices) {
    if (c == t) return t;
    list += (list.empty() ? "" : " | ") + c;
  }
  throw InputError(label, "value", "expected " + list + ", got '" + t + "'");
}

}  // namespace saresgs
