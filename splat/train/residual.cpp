#include "splat/train/residual.h"
#include "geometry/enum_names.h"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cmath>
#include <numeric>
#include <iterator>
#include <stdexcept>

#include <tbb/parallel_invoke.h>

#include "geometry/float_env.h"
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
  return enumName(r, std::array<const char*, 4>{"both", "opacity", "scale", "random"});
}

namespace {

std::size_t countOf(double fraction, std::size_t n) {
  const double f = std::clamp(fraction, 0.0, 1.0);
  return std::min(n, static_cast<std::size_t>(std::llround(f * static_cast<double>(n))));
}

// The ranking's and the draw's scratch, kept per thread between steps.
struct SubsetScratch {
  std::vector<std::uint64_t> keys, cand;
  std::vector<std::uint32_t> hist;
  std::vector<int> a, b;
  std::vector<std::uint8_t> chosen;
};

// The element of rank r (0-based) among distinct keys, by most-significant-digit radix
// selection: each round counts one 12-bit digit of the keys still in play, keeps those
// whose digit holds rank r (in sc.cand, filtered in place after the first round) and
// narrows r; the last few dozen are finished by nth_element. `keys` is not changed.
std::uint64_t kthSmallest(const std::vector<std::uint64_t>& keys, std::size_t r, SubsetScratch& sc) {
  constexpr int kDigit = 12;
  constexpr std::uint64_t kMask = (std::uint64_t{1} << kDigit) - 1;
  sc.hist.resize(kMask + 1);
  reserveKept(sc.cand, keys.size());  // the candidates never outgrow the keys: no reallocation below
  const std::uint64_t* src = keys.data();
  std::size_t len = keys.size();
  for (int shift = 64 - kDigit; shift >= 0 && len > 64; shift -= kDigit) {
    std::fill(sc.hist.begin(), sc.hist.end(), 0u);
    for (std::size_t i = 0; i < len; ++i) ++sc.hist[(src[i] >> shift) & kMask];
    std::uint64_t digit = 0;
    std::size_t below = 0;
    while (below + sc.hist[digit] <= r) below += sc.hist[digit++];
    if (sc.hist[digit] == len) continue;  // every key has this digit: nothing to drop
    if (src != sc.cand.data()) sc.cand.resize(sc.hist[digit]);
    std::uint64_t* dst = sc.cand.data();
    std::size_t m = 0;
    for (std::size_t i = 0; i < len; ++i)
      if (((src[i] >> shift) & kMask) == digit) dst[m++] = src[i];
    src = dst;
    len = m;
    r -= below;
  }
  if (src != sc.cand.data()) sc.cand.assign(src, src + len);
  const auto first = sc.cand.begin();
  std::nth_element(first, first + static_cast<std::ptrdiff_t>(r), first + static_cast<std::ptrdiff_t>(len));
  return sc.cand[r];
}

// The k smallest by (key, index), ascending by index, into `out`. The order is total, so
// the set is unique. Each (key, index) is one 64-bit integer that orders as the pair does
// (the key's bits mapped to an unsigned order, -0 as +0, above the index). The k-th
// smallest of them is found by radix selection (kthSmallest), and the set is then every
// key at or below it, listed by one scan in index order: this runs every residual
// training step, where a selection over all keys and a sort of the k indices cost about
// a millisecond at 40 000 Gaussians.
template <typename Key>
void topBy(std::size_t n, double fraction, Key key, SubsetScratch& sc, std::vector<int>& out) {
  const std::size_t k = countOf(fraction, n);
  out.clear();
  if (k == 0) return;
  std::vector<std::uint64_t>& keys = sc.keys;
  keys.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float v = key(static_cast<int>(i)) + 0.0f;  // -0 + 0 is +0; keys are never NaN
    const std::uint32_t b = std::bit_cast<std::uint32_t>(v);
    // ~b for negative keys, b with the sign bit set for the others (without a branch:
    // the scale keys' signs are mixed)
    const std::uint32_t ordered = b ^ (static_cast<std::uint32_t>(static_cast<std::int32_t>(b) >> 31) | 0x80000000u);
    keys[i] = (static_cast<std::uint64_t>(ordered) << 32) | static_cast<std::uint32_t>(i);
  }
  const std::uint64_t kth = kthSmallest(keys, k - 1, sc);
  out.resize(n);
  std::size_t m = 0;
  for (std::size_t i = 0; i < n; ++i) {  // branch-free: about one key in ten is kept
    out[m] = static_cast<int>(i);
    m += keys[i] <= kth ? 1 : 0;
  }
  out.resize(m);  // m == k: the keys are distinct
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
  std::size_t m = 0;
  for (std::size_t i = 0; i < n; ++i) {  // branch-free: the draw keeps a random nine in ten
    idx[m] = static_cast<int>(i);
    m += chosen[i];
  }
  idx.resize(m);  // m == k
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
  SubsetScratch sc;
  std::vector<int> out;
  topBy(
      g.size(), fraction, [&](int i) { return opacityKey(g, i); }, sc, out);
  return out;
}

std::vector<int> largestScale(const Gaussians& g, double fraction) {
  SubsetScratch sc;
  std::vector<int> out;
  topBy(
      g.size(), fraction, [&](int i) { return scaleKey(g, i); }, sc, out);
  return out;
}

ResidualSubset selectResidualSubset(const Gaussians& g, const ResidualOptions& opt, std::mt19937_64& rng) {
  ResidualSubset out;
  selectResidualSubset(g, opt, rng, out);
  return out;
}

void selectResidualSubset(const Gaussians& g, const ResidualOptions& opt, std::mt19937_64& rng, ResidualSubset& out) {
  const std::size_t n = g.size();
  out.mask.assign(n, 0);
  out.random.clear();
  out.uncertain.clear();
  if (n == 0) return;
  KeptBuffers<SubsetScratch> kept;
  SubsetScratch& sc = kept.get();
  auto opacity = [&](int i) { return opacityKey(g, i); };
  auto scale = [&](int i) { return scaleKey(g, i); };
  auto draw = [&] {
    const FloatEnvGuard fenv;  // geometry/float_env.h (a task body of ours)
    sampleWithoutReplacement(n, countOf(opt.alpha, n), rng, sc.chosen, out.random);
  };
  // The draw (serial in the generator) and the rankings (no generator) touch disjoint
  // data, so they run side by side; the result does not depend on how they are scheduled.
  // The random ranking uses the generator after the draw, so it runs after it.
  if (opt.ranking == UncertaintyRanking::kRandom) {
    draw();
    sampleWithoutReplacement(n, countOf(2 * opt.beta, n), rng, sc.chosen, out.uncertain);
  } else {
    tbb::parallel_invoke(draw, [&] {
      const FloatEnvGuard fenv;  // the keys are floats: DAZ would read a denormal as 0
      switch (opt.ranking) {
        case UncertaintyRanking::kBoth:
          topBy(n, opt.beta, opacity, sc, sc.a);
          topBy(n, opt.beta, scale, sc, sc.b);
          std::set_union(sc.a.begin(), sc.a.end(), sc.b.begin(), sc.b.end(), std::back_inserter(out.uncertain));
          break;
        case UncertaintyRanking::kOpacity:
          topBy(n, 2 * opt.beta, opacity, sc, out.uncertain);
          break;
        case UncertaintyRanking::kScale:
          topBy(n, 2 * opt.beta, scale, sc, out.uncertain);
          break;
        case UncertaintyRanking::kRandom:
          break;  // above
      }
    });
  }
  for (int i : out.random) out.mask[static_cast<std::size_t>(i)] = 1;
  for (int i : out.uncertain) out.mask[static_cast<std::size_t>(i)] = 1;
}

}  // namespace saresgs
