// The OpenVDB module (see vdb_backend.h): the only file that includes OpenVDB (~2 s per
// translation unit to parse), built as libsaresgs_vdb.so and loaded on first use.
#include <openvdb/openvdb.h>
#include <openvdb/tools/Morphology.h>

#include "geometry/occupancy/vdb_backend.h"

namespace {

using openvdb::Coord;
using openvdb::CoordBBox;
using MaskTree = openvdb::MaskTree;  // the tree of openvdb::MaskGrid: topology only

MaskTree& tree(void* t) { return *static_cast<MaskTree*>(t); }
const MaskTree& tree(const void* t) { return *static_cast<const MaskTree*>(t); }
Coord toCoord(const saresgs::Voxel& v) { return Coord(v[0], v[1], v[2]); }

openvdb::tools::NearestNeighbors neighbours(saresgs::DilationShape s) {
  switch (s) {
    case saresgs::DilationShape::FaceEdge:
      return openvdb::tools::NN_FACE_EDGE;
    case saresgs::DilationShape::Octahedron:
      return openvdb::tools::NN_FACE;
    case saresgs::DilationShape::Cube:
      break;
  }
  return openvdb::tools::NN_FACE_EDGE_VERTEX;
}

void* create() { return new MaskTree(); }
void* copy(const void* t) { return new MaskTree(tree(t)); }  // MaskTree's copy is deep
void destroy(void* t) { delete static_cast<MaskTree*>(t); }

void setOn(void* t, const saresgs::Voxel* v, std::size_t n) {
  openvdb::tree::ValueAccessor<MaskTree> acc(tree(t));
  for (std::size_t i = 0; i < n; ++i) acc.setValueOn(toCoord(v[i]));
}

bool isOn(const void* t, const saresgs::Voxel& v) { return tree(t).isValueOn(toCoord(v)); }

void filterKeys(const void* t, const saresgs::VoxelKey* keys, std::size_t n, std::vector<saresgs::VoxelKey>& out) {
  out.clear();
  openvdb::tree::ValueAccessor<const MaskTree> acc(tree(t));
  for (std::size_t i = 0; i < n; ++i)
    if (acc.isValueOn(toCoord(saresgs::unpackVoxel(keys[i])))) out.push_back(keys[i]);
}

void dilate(void* t, int radius, saresgs::DilationShape shape) {
  if (radius <= 0 || tree(t).empty()) return;
  // EXPAND_TILES keeps the result voxelized (no pruning into tiles); activeKeys expands
  // tiles anyway. OpenVDB threads this with TBB; topology union is order independent, so
  // the result is deterministic.
  openvdb::tools::dilateActiveValues(tree(t), radius, neighbours(shape), openvdb::tools::EXPAND_TILES);
}

void unite(void* t, const void* other) { tree(t).topologyUnion(tree(other)); }
void clear(void* t) { tree(t).clear(); }
bool empty(const void* t) { return tree(t).empty(); }
std::size_t activeCount(const void* t) { return static_cast<std::size_t>(tree(t).activeVoxelCount()); }

void activeKeys(const void* t, std::vector<saresgs::VoxelKey>& out) {
  out.clear();
  out.reserve(static_cast<std::size_t>(tree(t).activeVoxelCount()));
  auto add = [&](const Coord& c) {
    const saresgs::Voxel v{c.x(), c.y(), c.z()};
    if (saresgs::voxelRepresentable(v)) out.push_back(saresgs::packVoxel(v));
  };
  for (auto it = tree(t).cbeginValueOn(); it; ++it) {
    if (it.isVoxelValue()) {
      add(it.getCoord());
    } else {
      CoordBBox b;
      it.getBoundingBox(b);
      for (auto c = b.begin(); c; ++c) add(*c);
    }
  }
}

bool bounds(const void* t, saresgs::Voxel& lo, saresgs::Voxel& hi) {
  if (tree(t).empty()) return false;
  CoordBBox b;
  tree(t).evalActiveVoxelBoundingBox(b);
  lo = {b.min().x(), b.min().y(), b.min().z()};
  hi = {b.max().x(), b.max().y(), b.max().z()};
  return true;
}

std::size_t memUsage(const void* t) { return static_cast<std::size_t>(tree(t).memUsage()); }

constexpr saresgs::vdb_module::Backend kBackend{
    saresgs::vdb_module::kAbi, create, copy, destroy, setOn, isOn, filterKeys, dilate, unite, clear, empty, activeCount,
    activeKeys, bounds, memUsage};

}  // namespace

extern "C" __attribute__((visibility("default"))) const saresgs::vdb_module::Backend* saresgs_vdb_backend() {
  return &kBackend;
}
