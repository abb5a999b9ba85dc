#pragma once
// Whole-model operations that densification and the optimiser share: every array of a
// model (and of its gradient and Adam moments, which have the same shape) is gathered,
// so adding or removing Gaussians keeps all of them aligned.
#include <cstddef>
#include <span>
#include <vector>

#include "splat/gaussians.h"

namespace saresgs {

// A model holding src's Gaussians idx[0], idx[1], ... in that order (repeats allowed).
template <typename T>
GaussiansT<T> gatherGaussians(const GaussiansT<T>& src, std::span<const int> idx) {
  GaussiansT<T> out;
  out.max_sh_degree = src.max_sh_degree;
  out.resize(idx.size());
  // forEachArray visits the arrays in the same fixed order on both models.
  std::vector<const std::vector<T>*> from;
  src.forEachArray([&](const std::vector<T>& a, std::size_t) { from.push_back(&a); });
  std::size_t which = 0;
  out.forEachArray([&](std::vector<T>& a, std::size_t per) {
    const std::vector<T>& s = *from[which++];
    for (std::size_t j = 0; j < idx.size(); ++j)
      for (std::size_t k = 0; k < per; ++k) a[j * per + k] = s[static_cast<std::size_t>(idx[j]) * per + k];
  });
  return out;
}

// Appends b's Gaussians to a (same SH degree).
template <typename T>
void appendGaussians(GaussiansT<T>& a, const GaussiansT<T>& b) {
  std::vector<const std::vector<T>*> from;
  b.forEachArray([&](const std::vector<T>& x, std::size_t) { from.push_back(&x); });
  std::size_t which = 0;
  a.forEachArray([&](std::vector<T>& x, std::size_t) {
    const std::vector<T>& s = *from[which++];
    x.insert(x.end(), s.begin(), s.end());
  });
}

}  // namespace saresgs
