#pragma once
// Integer voxel coordinates and exact voxel sets.
//
// A voxel is an integer triple (i, j, k) of the occupancy grid's fine resolution (see
// occupancy_grid.h for how world points map to voxels). VoxelSet is the exact (no
// collision) encoding of a set of voxels: a sorted, duplicate-free vector of 64-bit keys,
// so that union, intersection, difference and symmetric difference are linear merges.
//
// Key order is "block-major": voxels are grouped by their 8x8x8 block (the leaf node
// size of the OpenVDB grids), blocks ordered by (bx, by, bz), voxels inside a block by
// (x, y, z). Grouping by block lets the frustum test reject whole blocks and still emit
// a sorted set without a sort. The order is fixed and platform independent.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace saresgs {

using Voxel = std::array<std::int32_t, 3>;
using VoxelKey = std::uint64_t;

// Coordinates representable in a key: [-kVoxelCoordLimit, kVoxelCoordLimit) per axis.
inline constexpr std::int32_t kVoxelCoordLimit = 1 << 20;

inline bool voxelRepresentable(const Voxel& v) {
  for (int a = 0; a < 3; ++a)
    if (v[a] < -kVoxelCoordLimit || v[a] >= kVoxelCoordLimit) return false;
  return true;
}

// Packs a representable voxel: 18 bits per block coordinate (x, y, z), then 3 bits per
// in-block coordinate (x, y, z); 63 bits in all. Coordinates are biased by 2^20, a
// multiple of 8, so block index = floor(c / 8) for negative coordinates too.
inline VoxelKey packVoxel(const Voxel& v) {
  VoxelKey blocks = 0, local = 0;
  for (int a = 0; a < 3; ++a) {
    const auto u = static_cast<std::uint64_t>(static_cast<std::int64_t>(v[a]) + kVoxelCoordLimit);
    blocks = (blocks << 18) | (u >> 3);
    local = (local << 3) | (u & 7u);
  }
  return (blocks << 9) | local;
}

inline Voxel unpackVoxel(VoxelKey key) {
  Voxel v;
  for (int a = 0; a < 3; ++a) {
    const int shift = 2 - a;  // x is the most significant of each group
    const std::uint64_t local = (key >> (3 * shift)) & 7u;
    const std::uint64_t block = (key >> (9 + 18 * shift)) & ((std::uint64_t{1} << 18) - 1);
    v[a] = static_cast<std::int32_t>(static_cast<std::int64_t>((block << 3) | local) - kVoxelCoordLimit);
  }
  return v;
}

// The 8x8x8 block a key belongs to (keys of one block are contiguous in key order).
inline std::uint64_t blockOfKey(VoxelKey key) { return key >> 9; }

class VoxelSet {
 public:
  VoxelSet() = default;
  // Any order, duplicates allowed. Throws InputError when a voxel is not representable.
  static VoxelSet fromVoxels(std::span<const Voxel> voxels);
  // Keys already strictly increasing (checked; throws std::invalid_argument otherwise).
  static VoxelSet fromSortedKeys(std::vector<VoxelKey> keys);

  std::size_t size() const { return keys_.size(); }
  bool empty() const { return keys_.empty(); }
  bool contains(const Voxel& v) const;
  const std::vector<VoxelKey>& keys() const { return keys_; }
  std::vector<Voxel> voxels() const;  // in key order
  bool operator==(const VoxelSet&) const = default;

 private:
  std::vector<VoxelKey> keys_;
};

VoxelSet setUnion(const VoxelSet& a, const VoxelSet& b);
VoxelSet setIntersection(const VoxelSet& a, const VoxelSet& b);
VoxelSet setDifference(const VoxelSet& a, const VoxelSet& b);  // a \ b
// Counts without building the sets.
std::size_t intersectionSize(const VoxelSet& a, const VoxelSet& b);
std::size_t differenceSize(const VoxelSet& a, const VoxelSet& b);           // |a \ b|
std::size_t symmetricDifferenceSize(const VoxelSet& a, const VoxelSet& b);  // |a xor b|

}  // namespace saresgs
