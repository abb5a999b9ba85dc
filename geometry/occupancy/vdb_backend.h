#pragma once
// What the OpenVDB module (libsaresgs_vdb.so, built from vdb_module.cpp) offers the rest of
// the program: a table of plain functions on topology-only OpenVDB trees (MaskTree) held
// behind opaque handles. The program loads the module the first time a grid is made
// (vdb_mask.cpp), so a process that never builds a grid never loads libopenvdb, whose
// ~69,000 symbol relocations cost about 60 ms at every start.
//
// Both sides are built by the same build with the same compiler, so the table may pass
// C++ types (std::vector); `abi` guards against a stale module from another build.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "geometry/occupancy/dilation_shape.h"
#include "geometry/occupancy/voxel_set.h"

namespace saresgs::vdb_module {

inline constexpr int kAbi = 2;

struct Backend {
  int abi;
  void* (*create)();                     // an empty tree
  void* (*copy)(const void* tree);       // a deep copy
  void (*destroy)(void* tree);
  void (*setOn)(void* tree, const Voxel* voxels, std::size_t n);
  bool (*isOn)(const void* tree, const Voxel& v);
  // The keys whose voxels are on, in the given order, through one accessor.
  void (*filterKeys)(const void* tree, const VoxelKey* keys, std::size_t n, std::vector<VoxelKey>& out);
  void (*dilate)(void* tree, int radius, saresgs::DilationShape shape);
  void (*unite)(void* tree, const void* other);  // topology union
  void (*clear)(void* tree);
  bool (*empty)(const void* tree);
  std::size_t (*activeCount)(const void* tree);
  // The keys of every representable active voxel, active tiles expanded voxel by voxel, in
  // the tree's order (not key order).
  void (*activeKeys)(const void* tree, std::vector<VoxelKey>& out);
  // Inclusive bounds of the active voxels; false for an empty tree.
  bool (*bounds)(const void* tree, Voxel& lo, Voxel& hi);
  std::size_t (*memUsage)(const void* tree);
};

}  // namespace saresgs::vdb_module

// The module's one exported symbol.
extern "C" const saresgs::vdb_module::Backend* saresgs_vdb_backend();
