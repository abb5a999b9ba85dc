#include "splat/train/residual.h"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cmath>
#include <numeric>
#include <iterator>
#include <stdexcept>

#include "splat/kept_buffers.h"

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

// The ranking's and the draw's scratch, kept per thread between steps.
struct SubsetScratch {
  std::vector<std::uint64_t> keys;
  std::vector<int> a, b;
  std::vector<std::uint8_t> chosen;
};

// The k smallest by (key, index), ascending by index, into `out`. The order is total, so
// the set is unique: keys are computed once (not per comparison) and the k-th element is
// found by selection rather than by a partial sort, which runs every residual training
// step. Each (key, index) is one 64-bit integer that orders as the pair does (the key's
// bits mapped to an unsigned order, -0 as +0, above the index), so the selection compares
// integers in place instead of looking two keys up per comparison.
template <typename Key>
void topBy(std::size_t n, double fraction, Key key, std::vector<std::uint64_t>& keys, std::vector<int>& out) {
  const std::size_t k = countOf(fraction, n);
  keys.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float v = key(static_cast<int>(i)) + 0.0f;  // -0 + 0 is +0; keys are never NaN
    const std::uint32_t b = std::bit_cast<std::uint32_t>(v);
    const std::uint32_t ordered = (b & 0x80000000u) ? ~b : (b | 0x80000000u);
    keys[i] = (static_cast<std::uint64_t>(ordered) << 32) | static_cast<std::uint32_t>(i);
  }
  if (k < n) std::nth_element(keys.begin(), keys.begin() + static_cast<std::ptrdiff_t>(k), keys.end());
  out.resize(k);
  for (std::size_t j = 0; j < k; ++j) out[j] = static_cast<int>(keys[j] & 0xffffffffu);
  std::sort(out.begin(), out.end());
}

// k distinct indices of [0, n) (partial Fisher-Yates), ascending, into `out`. They are
// listed by marking and scanning rather than by sorting (same set, same order, O(n)).
void sampleWithoutReplacement(std::size_t n, std::size_t k, std::mt19937_64& rng, std::vector<std::uint8_t>& chosen,
                              std::vector<int>& out) {
  std::vector<int>& idx = out;
  idx.resize(n);
  std::iota(idx.begin(), idx.end(), 0);
  for (std::size_t i = 0; i < k; ++i) {
    std::uniform_int_distribution<std::size_t> pick(i, n - 1);
    std::swap(idx[i], idx[pick(rng)]);
  }
  chosen.assign(n, 0);
  for (std::size_t i = 0; i < k; ++i) chosen[static_cast<std::size_t>(idx[i])] = 1;
  idx.clear();
  for (std::size_t i = 0; i < n; ++i)
    if (chosen[i]) idx.push_back(static_cast<int>(i));
}

float opacityKey(const Gaussians& g, int i) {
  // NaN keys would break the ordering; they rank as most uncertain.
  const float o = g.opacities[static_cast<std::size_t>(i)];
  return std::isnan(o) ? -INFINITY : o;
}
float scaleKey(const Gaussians& g, int i) {
  const std::size_t j = 3 * static_cast<std::size_t>(i);
  const float s = std::max({g.log_scales[j], g.log_scales[j + 1], g.log_scales[j + 2]});
  return std::isnan(s) ? -INFINITY : -s;
}

}  // namespace

std::vector<int> lowestOpacity(const Gaussians& g, double fraction) {
  std::vector<std::uint64_t> keys;
  std::vector<int> out;
  topBy(g.size(), fraction, [&](int i) { return opacityKey(g, i); }, keys, out);
  return out;
}

std::vector<int> largestScale(const Gaussians& g, double fraction) {
  std::vector<std::uint64_t> keys;
  std::vector<int> out;
  topBy(g.size(), fraction, [&](int i) { return scaleKey(g, i); }, keys, out);
  return out;
}

ResidualSubset selectResidualSubset(const Gaussians& g, const ResidualOptions& opt, std::mt19937_64& rng) {
  ResidualSubset out;
  selectResidualSubset(g, opt, rng, out);
  return out;
}

void selectResidualSubset(const Gaussians& g, const ResidualOptions& opt, std::mt19937_64& rng,
                          ResidualSubset& out) {
  const std::size_t n = g.size();
  out.mask.assign(n, 0);
  out.random.clear();
  out.uncertain.clear();
  if (n == 0) return;
  KeptBuffers<SubsetScratch> kept;
  SubsetScratch& sc = kept.get();
  auto opacity = [&](int i) { return opacityKey(g, i); };
  auto scale = [&](int i) { return scaleKey(g, i); };
  sampleWithoutReplacement(n, countOf(opt.alpha, n), rng, sc.chosen, out.random);
  switch (opt.ranking) {
    case UncertaintyRanking::kBoth:
      topBy(n, opt.beta, opacity, sc.keys, sc.a);
      topBy(n, opt.beta, scale, sc.keys, sc.b);
      std::set_union(sc.a.begin(), sc.a.end(), sc.b.begin(), sc.b.end(), std::back_inserter(out.uncertain));
      break;
    case UncertaintyRanking::kOpacity: topBy(n, 2 * opt.beta, opacity, sc.keys, out.uncertain); break;
    case UncertaintyRanking::kScale: topBy(n, 2 * opt.beta, scale, sc.keys, out.uncertain); break;
    case UncertaintyRanking::kRandom:
      sampleWithoutReplacement(n, countOf(2 * opt.beta, n), rng, sc.chosen, out.uncertain);
      break;
  }
  for (int i : out.random) out.mask[static_cast<std::size_t>(i)] = 1;
  for (int i : out.uncertain) out.mask[static_cast<std::size_t>(i)] = 1;
}

}  // namespace saresgs
