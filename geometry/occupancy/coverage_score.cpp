#include "geometry/occupancy/coverage_score.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <numeric>
#include <string>

#include "geometry/error.h"
#include "geometry/float_env.h"

namespace saresgs {

std::uint32_t spatialHash(const Voxel& v, std::uint32_t table_size) {
  // Instant-NGP's primes; products wrap modulo 2^32 (unsigned arithmetic), negative
  // coordinates included. T is a power of two, so "mod T" keeps the low bits.
  const auto x = static_cast<std::uint32_t>(v[0]);
  const auto y = static_cast<std::uint32_t>(v[1]);
  const auto z = static_cast<std::uint32_t>(v[2]);
  const std::uint32_t h = (x * 1u) ^ (y * 2654435761u) ^ (z * 805459861u);
  return h & (table_size - 1u);
}

HashedBits::HashedBits(std::size_t table_size) : size_(table_size) {
  if (table_size < 2 || table_size > (std::size_t{1} << 30) || !std::has_single_bit(table_size))
    throw InputError("hash encoding", "table_size",
                     "expected a power of two in [2, 2^30], got " + std::to_string(table_size));
  words_.assign((table_size + 63) / 64, 0);
}

HashedBits HashedBits::encode(const VoxelSet& voxels, std::size_t table_size) {
  HashedBits b(table_size);
  for (VoxelKey k : voxels.keys()) b.insert(unpackVoxel(k));
  return b;
}

std::size_t HashedBits::count() const {
  std::size_t n = 0;
  for (std::uint64_t w : words_) n += static_cast<std::size_t>(std::popcount(w));
  return n;
}

CoverageScore scoreHashed(const HashedBits& observed, const HashedBits& candidate) {
  if (observed.size() != candidate.size())
    throw InputError("hash encoding", "table_size",
                     "observed and candidate bits differ in size (" + std::to_string(observed.size()) + " vs " +
                         std::to_string(candidate.size()) + ")");
  CoverageScore s;
  const auto& a = observed.words();
  const auto& b = candidate.words();
  for (std::size_t i = 0; i < a.size(); ++i) {
    s.differing += static_cast<std::size_t>(std::popcount(a[i] ^ b[i]));
    s.new_count += static_cast<std::size_t>(std::popcount(b[i] & ~a[i]));
  }
  s.hamming = static_cast<double>(s.differing) / static_cast<double>(observed.size());
  return s;
}

CoverageScore scoreExact(const VoxelSet& observed, const VoxelSet& candidate, std::size_t universe) {
  CoverageScore s;
  const std::size_t common = intersectionSize(observed, candidate);
  s.differing = observed.size() + candidate.size() - 2 * common;
  s.new_count = candidate.size() - common;
  s.hamming = universe > 0 ? static_cast<double>(s.differing) / static_cast<double>(universe) : 0.0;
  return s;
}

std::vector<CoverageScore> scoreCandidates(const VoxelSet& observed, std::span<const VoxelSet> candidates,
                                           std::size_t universe, const CoverageScoring& opts) {
  std::vector<CoverageScore> out(candidates.size());
  if (opts.encoding == CoverageEncoding::Exact) {
    tbb::parallel_for(std::size_t{0}, candidates.size(), [&](std::size_t j) {
      const FloatEnvGuard fenv;  // geometry/float_env.h
      out[j] = scoreExact(observed, candidates[j], universe);
    });
    return out;
  }
  // Same numbers as scoreHashed on two dense T-bit vectors, without touching all T bits
  // per candidate: with B = the candidate's buckets (distinct) and c = |B & b_obs|,
  // popcount(b_obs XOR b_cand) = |b_obs| + |B| - 2c and popcount(b_cand & ~b_obs) = |B| - c.
  const HashedBits obs = HashedBits::encode(observed, opts.table_size);
  const std::size_t obs_bits = obs.count();
  const auto T = static_cast<std::uint32_t>(opts.table_size);
  // Each thread dedups buckets in its own T-bit scratch vector, cleared again bucket by
  // bucket, so a candidate costs O(|candidate|), not O(T). Counts do not depend on the
  // order, so the result does not depend on the thread schedule.
  tbb::enumerable_thread_specific<HashedBits> scratch([&] { return HashedBits(opts.table_size); });
  tbb::parallel_for(std::size_t{0}, candidates.size(), [&](std::size_t j) {
    const FloatEnvGuard fenv;  // geometry/float_env.h
    HashedBits& seen = scratch.local();
    std::size_t distinct = 0, common = 0;
    for (VoxelKey k : candidates[j].keys()) {
      const std::uint32_t b = spatialHash(unpackVoxel(k), T);
      if (seen.test(b)) continue;
      seen.set(b);
      ++distinct;
      common += obs.test(b);
    }
    for (VoxelKey k : candidates[j].keys()) seen.reset(spatialHash(unpackVoxel(k), T));
    CoverageScore& s = out[j];
    s.differing = obs_bits + distinct - 2 * common;
    s.new_count = distinct - common;
    s.hamming = static_cast<double>(s.differing) / static_cast<double>(opts.table_size);
  });
  return out;
}

double criterionValue(const CoverageScore& s, CoverageCriterion c) {
  return c == CoverageCriterion::Hamming ? s.hamming : static_cast<double>(s.new_count);
}

HashLoad hashLoad(const VoxelSet& voxels, std::size_t table_size) {
  const HashedBits bits = HashedBits::encode(voxels, table_size);
  HashLoad h;
  h.voxels = voxels.size();
  h.table_size = table_size;
  h.bits_set = bits.count();
  h.colliding = h.voxels - h.bits_set;
  h.load = static_cast<double>(h.voxels) / static_cast<double>(table_size);
  return h;
}

std::size_t hashTableSizeFor(std::size_t voxels, double max_load, int min_bits, int max_bits) {
  for (int k = min_bits; k < max_bits; ++k)
    if (static_cast<double>(voxels) <= max_load * static_cast<double>(std::size_t{1} << k)) return std::size_t{1} << k;
  return std::size_t{1} << max_bits;
}

}  // namespace saresgs
