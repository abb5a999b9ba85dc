#pragma once
// An enumerator's name from a table written in the enum's declaration order: one line per
// enum instead of a switch per enum. The enum must count from 0 without gaps; a value
// outside the table gives `fallback`.
#include <array>
#include <cstddef>

namespace saresgs {

template <typename E, std::size_t N>
constexpr const char* enumName(E e, const std::array<const char*, N>& names, const char* fallback = "?") {
  const auto i = static_cast<std::size_t>(e);
  return i < N ? names[i] : fallback;
}

}  // namespace saresgs
