#include "splat/train/residual.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace saresgs {

UncertaintyRanking parseUncertaintyRanking(const std::string& s) {
  if (s == "both") return UncertaintyRanking::kBoth;
  if (s == "opacity") return UncertaintyRanking::kOpacity;
  if (s == "scale") return UncertaintyRanking::kScale;
  if (s == "random") return UncertaintyRanking::kRandom;
  throw std::invalid_argument("uncertainty ranking '" + s + "': expected both, opacity, scale or random");
}

const char* toString(UncertaintyRanking r) {
  switch (r) {
    case UncertaintyRanking::kBoth: return "both";
    case UncertaintyRanking::kOpacity: return "opacity";
    case UncertaintyRanking::kScale: return "scale";
    case UncertaintyRanking::kRandom: return "random";
  }
  return "?";
}

namespace {

std::size_t countOf(double fraction, std::size_t n) {
  const double f = std::clamp(fraction, 0.0, 1.0);
  return std::min(n, static_cast<std::size_t>(std::llround(f * static_cast<double>(n))));
}

// The k smallest by (key, index), ascending by index. The order is total, so the set is
// unique: keys are computed once (not per comparison) and the k-th element is found by
// selection rather than by a partial sort, which runs every residual training step.
template <typename Key>
std::vector<int> topBy(std::size_t n, double fraction, Key key) {
  const std::size_t k = countOf(fraction, n);
  std::vector<float> keys(n);
  for (std::size_t i = 0; i < n; ++i) keys[i] = key(static_cast<int>(i));
  std::vector<int> idx(n);
  std::iota(idx.begin(), idx.end(), 0);
  auto less = [&](int a, int b) {
    const float ka = keys[static_cast<std::size_t>(a)], kb = keys[static_cast<std::size_t>(b)];
    return ka != kb ? ka < kb : a < b;
  };
  if (k < n) std::nth_element(idx.begin(), idx.begin() + static_cast<std::ptrdiff_t>(k), idx.end(), less);
  idx.resize(k);
  std::sort(idx.begin(), idx.end());
  return idx;
}

// k distinct indices of [0, n) (partial Fisher-Yates), ascending. They are listed by
// marking and scanning rather than by sorting (same set, same order, O(n)).
std::vector<int> sampleWithoutReplacement(std::size_t n, std::size_t k, std::mt19937_64& rng) {
  std::vector<int> idx(n);
  std::iota(idx.begin(), idx.end(), 0);
  for (std::size_t i = 0; i < k; ++i) {
    std::uniform_int_distribution<std::size_t> pick(i, n - 1);
    std::swap(idx[i], idx[pick(rng)]);
  }
  std::vector<std::uint8_t> chosen(n, 0);
  for (std::size_t i = 0; i < k; ++i) chosen[static_cast<std::size_t>(idx[i])] = 1;
  idx.clear();
  for (std::size_t i = 0; i < n; ++i)
    if (chosen[i]) idx.push_back(static_cast<int>(i));
  return idx;
}

}  // namespace

std::vector<int> lowestOpacity(const Gaussians& g, double fraction) {
  // NaN keys would break the ordering; they rank as most uncertain.
  return topBy(g.size(), fraction, [&](int i) {
    const float o = g.opacities[static_cast<std::size_t>(i)];
    return std::isnan(o) ? -INFINITY : o;
  });
}

std::vector<int> largestScale(const Gaussians& g, double fraction) {
  return topBy(g.size(), fraction, [&](int i) {
    const std::size_t j = 3 * static_cast<std::size_t>(i);
    const float s = std::max({g.log_scales[j], g.log_scales[j + 1], g.log_scales[j + 2]});
    return std::isnan(s) ? -INFINITY : -s;
  });
}

ResidualSubset selectResidualSubset(const Gaussians& g, const ResidualOptions& opt, std::mt19937_64& rng) {
  const std::size_t n = g.size();
  ResidualSubset out;
  out.mask.assign(n, 0);
  if (n == 0) return out;
  out.random = sampleWithoutReplacement(n, countOf(opt.alpha, n), rng);
  switch (opt.ranking) {
    case UncertaintyRanking::kBoth: {
      const auto a = lowestOpacity(g, opt.beta), b = largestScale(g, opt.beta);
      std::set_union(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(out.uncertain));
      break;
    }
    case UncertaintyRanking::kOpacity: out.uncertain = lowestOpacity(g, 2 * opt.beta); break;
    case UncertaintyRanking::kScale: out.uncertain = largestScale(g, 2 * opt.beta); break;
    case UncertaintyRanking::kRandom:
      out.uncertain = sampleWithoutReplacement(n, countOf(2 * opt.beta, n), rng);
      break;
  }
  for (int i : out.random) out.mask[static_cast<std::size_t>(i)] = 1;
  for (int i : out.uncertain) out.mask[static_cast<std::size_t>(i)] = 1;
  return out;
}

}  // namespace saresgs
