#include "geometry/occupancy/voxel_set.h"

#include <algorithm>
#include <iterator>
#include <stdexcept>
#include <string>

#include "geometry/error.h"

namespace saresgs {

VoxelSet VoxelSet::fromVoxels(std::span<const Voxel> voxels) {
  VoxelSet s;
  s.keys_.reserve(voxels.size());
  for (std::size_t i = 0; i < voxels.size(); ++i) {
    if (!voxelRepresentable(voxels[i]))
      throw InputError("voxel set", "voxel " + std::to_string(i), "expected coordinates in [-2^20, 2^20)");
    s.keys_.push_back(packVoxel(voxels[i]));
  }
  std::sort(s.keys_.begin(), s.keys_.end());
  s.keys_.erase(std::unique(s.keys_.begin(), s.keys_.end()), s.keys_.end());
  return s;
}

VoxelSet VoxelSet::fromSortedKeys(std::vector<VoxelKey> keys) {
  for (std::size_t i = 1; i < keys.size(); ++i)
    if (!(keys[i - 1] < keys[i])) throw std::invalid_argument("VoxelSet::fromSortedKeys: keys not strictly increasing");
  VoxelSet s;
  s.keys_ = std::move(keys);
  return s;
}

bool VoxelSet::contains(const Voxel& v) const {
  return voxelRepresentable(v) && std::binary_search(keys_.begin(), keys_.end(), packVoxel(v));
}

std::vector<Voxel> VoxelSet::voxels() const {
  std::vector<Voxel> out;
  out.reserve(keys_.size());
  for (VoxelKey k : keys_) out.push_back(unpackVoxel(k));
  return out;
}

VoxelSet setUnion(const VoxelSet& a, const VoxelSet& b) {
  std::vector<VoxelKey> out;
  out.reserve(a.size() + b.size());
  std::set_union(a.keys().begin(), a.keys().end(), b.keys().begin(), b.keys().end(), std::back_inserter(out));
  return VoxelSet::fromSortedKeys(std::move(out));
}

VoxelSet setIntersection(const VoxelSet& a, const VoxelSet& b) {
  std::vector<VoxelKey> out;
  std::set_intersection(a.keys().begin(), a.keys().end(), b.keys().begin(), b.keys().end(), std::back_inserter(out));
  return VoxelSet::fromSortedKeys(std::move(out));
}

VoxelSet setDifference(const VoxelSet& a, const VoxelSet& b) {
  std::vector<VoxelKey> out;
  std::set_difference(a.keys().begin(), a.keys().end(), b.keys().begin(), b.keys().end(), std::back_inserter(out));
  return VoxelSet::fromSortedKeys(std::move(out));
}

std::size_t intersectionSize(const VoxelSet& a, const VoxelSet& b) {
  // One merge pass; no allocation (scores are computed for every candidate).
  const auto& x = a.keys();
  const auto& y = b.keys();
  std::size_t i = 0, j = 0, n = 0;
  while (i < x.size() && j < y.size()) {
    if (x[i] < y[j])
      ++i;
    else if (y[j] < x[i])
      ++j;
    else {
      ++n;
      ++i;
      ++j;
    }
  }
  return n;
}

std::size_t differenceSize(const VoxelSet& a, const VoxelSet& b) { return a.size() - intersectionSize(a, b); }

std::size_t symmetricDifferenceSize(const VoxelSet& a, const VoxelSet& b) {
  return a.size() + b.size() - 2 * intersectionSize(a, b);
}

}  // namespace saresgs
