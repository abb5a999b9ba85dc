#pragma once
// Whether a JSON number converts to an integer type without loss. nlohmann's get<T>()
// casts a float outside T's range (undefined behaviour: 1e30 as an int) and wraps a
// negative integer into an unsigned type, so readers check with this first.
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

namespace saresgs {

// True for an integer within T's range, or a whole finite float within it; false for
// anything else (another type included).
template <typename T>
bool jsonIsExact(const nlohmann::json& v) {
  static_assert(std::is_integral_v<T> && !std::is_same_v<T, bool>);
  using L = std::numeric_limits<T>;
  if (v.is_number_unsigned()) return v.get<std::uint64_t>() <= static_cast<std::uint64_t>(L::max());
  if (v.is_number_integer()) {
    const std::int64_t x = v.get<std::int64_t>();
    if constexpr (std::is_signed_v<T>) return x >= static_cast<std::int64_t>(L::min()) && x <= static_cast<std::int64_t>(L::max());
    return x >= 0 && static_cast<std::uint64_t>(x) <= static_cast<std::uint64_t>(L::max());
  }
  if (v.is_number_float()) {
    const double x = v.get<double>();
    // L::min() is 0 or -2^digits and 2^digits is one past L::max(): both exact doubles.
    return std::isfinite(x) && x == std::floor(x) && x >= static_cast<double>(L::min()) &&
           x < std::ldexp(1.0, L::digits);
  }
  return false;
}

}  // namespace saresgs
