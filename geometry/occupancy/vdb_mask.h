#pragma once
// A topology-only sparse voxel mask: an OpenVDB MaskTree, reached through the OpenVDB
// module (vdb_backend.h), which the first mask made loads. A value type: copies are deep.
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "geometry/occupancy/dilation_shape.h"
#include "geometry/occupancy/voxel_set.h"

namespace saresgs {

namespace vdb_module {
struct Backend;
}

class VdbMask {
 public:
  // An empty mask. Loads the module on first use; throws std::runtime_error naming the
  // paths tried when it cannot be loaded.
  VdbMask();
  VdbMask(const VdbMask& o);
  VdbMask& operator=(const VdbMask& o);
  VdbMask(VdbMask&& o) noexcept;
  VdbMask& operator=(VdbMask&& o) noexcept;
  ~VdbMask();

  void setOn(std::span<const Voxel> voxels);
  bool isOn(const Voxel& v) const;
  // The keys of `set` whose voxels are on, in the set's order.
  VoxelSet filter(const VoxelSet& set) const;
  void dilate(int radius, DilationShape shape);  // radius <= 0: unchanged
  void unite(const VdbMask& o);
  void clear();
  bool empty() const;
  std::size_t activeCount() const;
  // The active voxels that keys can represent, as a set.
  VoxelSet keys() const;
  // Inclusive bounds of the active voxels; false when the mask is empty.
  bool bounds(Voxel& lo, Voxel& hi) const;
  std::size_t memUsage() const;

 private:
  const vdb_module::Backend* ops_;
  void* tree_;
};

// Where the OpenVDB module was loaded from (loading it if it was not), for messages.
std::string vdbModulePath();

}  // namespace saresgs
