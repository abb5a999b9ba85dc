#pragma once
// Encodings of voxel sets and the prefilter scores of SA-ResGS (paper Sec. 3.2, Eq. 3):
//   hashed  a bit vector b of T bits; voxel x sets bit h(x) with the Instant-NGP spatial
//           hash h(x) = (x0 * 1 XOR x1 * 2654435761 XOR x2 * 805459861) mod T in uint32
//           arithmetic (T a power of two, 2^11..2^19 in the paper's ablation);
//   exact   the VoxelSet itself (no collisions; the paper's "direct indexing" variant).
// Scores of a candidate against the observed set:
//   hamming     d_j = |b_obs XOR b_cand| / K: the paper's normalised Hamming distance.
//               K = T for hashed bits; for exact sets K = the caller's universe size
//               (the number of scene-occupied voxels: V in the paper).
//   new_count   |cand \ obs|: "how many newly covered voxels a candidate adds", the
//               paper's prose reading of d_j (for hashed bits: popcount(b_cand & ~b_obs)).
// Both are kept so that the ablation can tell them apart.
// Typical use (the paper's V_obs is a subset of the scene voxels V):
//   observed = grids.observedSceneVoxels(); universe = grids.sceneCount();
//   candidates[j] = frustumSet(grids, cam_j) or tracer.visibleSet(cam_j, stride);
//   scores = scoreCandidates(observed, candidates, universe, scoring);
// and the prefilter (nbv/coverage_prefilter.h) keeps the top N % by criterionValue.
// Observed voxels outside V would add the same count to every candidate's exact XOR
// (no effect on the ranking) and only collision noise to the hashed one.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "geometry/occupancy/voxel_set.h"

namespace saresgs {

// h(x) for a power-of-two table size T (uint32 wrap-around products, then the low bits).
std::uint32_t spatialHash(const Voxel& v, std::uint32_t table_size);

class HashedBits {
 public:
  // Throws InputError("hash encoding", "table_size", ...) unless T is a power of two in
  // [2, 2^30].
  explicit HashedBits(std::size_t table_size);
  static HashedBits encode(const VoxelSet& voxels, std::size_t table_size);

  void insert(const Voxel& v) { set(spatialHash(v, static_cast<std::uint32_t>(size_))); }
  void set(std::uint32_t bit) { words_[bit >> 6] |= std::uint64_t{1} << (bit & 63); }
  void reset(std::uint32_t bit) { words_[bit >> 6] &= ~(std::uint64_t{1} << (bit & 63)); }
  bool test(std::uint32_t bit) const { return (words_[bit >> 6] >> (bit & 63)) & 1u; }
  std::size_t size() const { return size_; }  // T
  std::size_t count() const;                  // set bits
  const std::vector<std::uint64_t>& words() const { return words_; }

 private:
  std::size_t size_ = 0;
  std::vector<std::uint64_t> words_;
};

struct CoverageScore {
  double hamming = 0.0;       // differing / K, in [0, 1] when K covers both sets
  std::size_t differing = 0;  // |obs XOR cand| (bits or voxels)
  std::size_t new_count = 0;  // |cand \ obs| (bits or voxels)
};

// Throws InputError("hash encoding", "table_size", ...) when the sizes differ.
CoverageScore scoreHashed(const HashedBits& observed, const HashedBits& candidate);
// `universe` = K; 0 gives hamming = 0 (an empty grid has nothing to differ on).
CoverageScore scoreExact(const VoxelSet& observed, const VoxelSet& candidate, std::size_t universe);

enum class CoverageEncoding { Hashed, Exact };
enum class CoverageCriterion { Hamming, NewCount };

// How candidate sets are encoded and scored against the observed set.
struct CoverageScoring {
  CoverageEncoding encoding = CoverageEncoding::Hashed;
  CoverageCriterion criterion = CoverageCriterion::Hamming;
  std::size_t table_size = std::size_t{1} << 19;  // T for the hashed encoding
};

// Scores every candidate set against the observed set with the chosen encoding
// (`universe` = K for the exact Hamming distance). Candidates are scored in parallel
// into fixed slots; the result does not depend on the thread count.
std::vector<CoverageScore> scoreCandidates(const VoxelSet& observed, std::span<const VoxelSet> candidates,
                                           std::size_t universe, const CoverageScoring& opts);
// The value ranked by the prefilter: hamming or new_count.
double criterionValue(const CoverageScore& s, CoverageCriterion c);

// How full a hash table of T bits is when `voxels` are hashed into it (the paper hashes
// only occupied voxels and relies on "the effective load factor of the hash table"
// staying low): load = |voxels| / T; bits_set = distinct bits hit; colliding =
// |voxels| - bits_set, the voxels that share a bit with an earlier one.
struct HashLoad {
  std::size_t voxels = 0, table_size = 0, bits_set = 0, colliding = 0;
  double load = 0.0;
};
// Throws InputError("hash encoding", "table_size", ...) as HashedBits does.
HashLoad hashLoad(const VoxelSet& voxels, std::size_t table_size);
// The smallest power of two T = 2^K, K in [min_bits, max_bits], with voxels / T <=
// max_load (2^max_bits when none is large enough).
std::size_t hashTableSizeFor(std::size_t voxels, double max_load = 0.5, int min_bits = 11, int max_bits = 19);

}  // namespace saresgs
