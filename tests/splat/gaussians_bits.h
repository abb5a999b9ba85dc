#pragma once
// Bit-for-bit comparison of two models' arrays, or of two value lists, shared by the tests
// that hold a fast path to its reference value by value (the projection kernels, Adam's
// vector loops, the kernel sets against each other).
#include <gtest/gtest.h>

#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "splat/gaussians.h"

namespace saresgs::test {

// Success when every array of `got` has `want`'s size and bits (-0 and +0 differ, equal
// NaN payloads agree); otherwise the first difference, by array and entry.
inline ::testing::AssertionResult arraysBitEqual(const Gaussians& got, const Gaussians& want) {
  std::vector<const std::vector<float>*> w;
  want.forEachArray([&](const std::vector<float>& a, std::size_t) { w.push_back(&a); });
  std::size_t array = 0;
  ::testing::AssertionResult result = ::testing::AssertionSuccess();
  bool failed = false;
  got.forEachArray([&](const std::vector<float>& a, std::size_t) {
    const std::size_t index = array++;
    if (failed) return;
    if (index >= w.size()) {
      result = ::testing::AssertionFailure() << "array " << index << " is not in the reference";
      failed = true;
      return;
    }
    const std::vector<float>& b = *w[index];
    if (a.size() != b.size()) {
      result = ::testing::AssertionFailure() << "array " << index << ": size " << a.size() << " vs " << b.size();
      failed = true;
      return;
    }
    for (std::size_t k = 0; k < a.size(); ++k)
      if (std::bit_cast<std::uint32_t>(a[k]) != std::bit_cast<std::uint32_t>(b[k])) {
        result = ::testing::AssertionFailure() << "array " << index << " entry " << k << ": " << a[k] << " vs " << b[k];
        failed = true;
        return;
      }
  });
  if (!failed && array != w.size())
    result = ::testing::AssertionFailure() << array << " arrays against the reference's " << w.size();
  return result;
}

// `head` followed by every array of `g`: a backward pass's whole output as one vector.
inline std::vector<float> flattened(std::vector<float> head, const Gaussians& g) {
  g.forEachArray([&](const std::vector<float>& a, std::size_t) { head.insert(head.end(), a.begin(), a.end()); });
  return head;
}

// Success when `got` has `want`'s size and bits, value by value; otherwise the first
// difference, the two values named `got_name` and `want_name`.
inline ::testing::AssertionResult valuesBitEqual(const std::vector<float>& got, const std::vector<float>& want,
                                                 const char* got_name = "got", const char* want_name = "want") {
  if (got.size() != want.size()) return ::testing::AssertionFailure() << "size " << got.size() << " vs " << want.size();
  for (std::size_t k = 0; k < got.size(); ++k)
    if (std::bit_cast<std::uint32_t>(got[k]) != std::bit_cast<std::uint32_t>(want[k]))
      return ::testing::AssertionFailure()
             << "entry " << k << ": " << got_name << " " << got[k] << ", " << want_name << " " << want[k];
  return ::testing::AssertionSuccess();
}

// Calls f(a's array, b's array, name) for each of the five parameter arrays, in
// forEachArray's order: an array-by-array comparison of two models of any scalar types.
template <typename A, typename B, typename F>
void forEachArrayPair(const GaussiansT<A>& a, const GaussiansT<B>& b, F&& f) {
  f(a.means, b.means, "means");
  f(a.log_scales, b.log_scales, "log_scales");
  f(a.rotations, b.rotations, "rotations");
  f(a.opacities, b.opacities, "opacities");
  f(a.sh, b.sh, "sh");
}

// How many values of `after` differ from `before`'s (the models have the same shape).
inline int countChanged(const Gaussians& before, const Gaussians& after) {
  std::vector<const std::vector<float>*> b;
  before.forEachArray([&](const std::vector<float>& a, std::size_t) { b.push_back(&a); });
  std::size_t array = 0;
  int changed = 0;
  after.forEachArray([&](const std::vector<float>& a, std::size_t) {
    for (std::size_t k = 0; k < a.size(); ++k) changed += a[k] != (*b[array])[k];
    ++array;
  });
  return changed;
}

}  // namespace saresgs::test
