// The only file that includes OpenVDB (its headers cost ~2 s per translation unit).
#include "geometry/occupancy/occupancy_grid.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Morphology.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "geometry/error.h"

namespace saresgs {

namespace {

using openvdb::Coord;
using openvdb::CoordBBox;
using MaskTree = openvdb::MaskTree;  // the tree of openvdb::MaskGrid: topology only

Coord toCoord(const Voxel& v) { return Coord(v[0], v[1], v[2]); }
Voxel toVoxel(const Coord& c) { return {c.x(), c.y(), c.z()}; }

// Calls f(Coord) for every active voxel, active tiles included (expanded voxel by
// voxel), so that the result does not depend on how OpenVDB chose to store the topology.
template <typename TreeT, typename F>
void forEachActiveVoxel(const TreeT& tree, F&& f) {
  for (auto it = tree.cbeginValueOn(); it; ++it) {
    if (it.isVoxelValue()) {
      f(it.getCoord());
    } else {
      CoordBBox b;
      it.getBoundingBox(b);
      for (auto c = b.begin(); c; ++c) f(*c);
    }
  }
}

// Sorted keys of the active voxels of a mask; voxels outside the key range are dropped.
VoxelSet keysOf(const MaskTree& tree) {
  std::vector<VoxelKey> keys;
  keys.reserve(tree.activeVoxelCount());
  forEachActiveVoxel(tree, [&](const Coord& c) {
    const Voxel v = toVoxel(c);
    if (voxelRepresentable(v)) keys.push_back(packVoxel(v));
  });
  // Tree iteration order (by child index inside each internal node) is not key order.
  std::sort(keys.begin(), keys.end());
  return VoxelSet::fromSortedKeys(std::move(keys));
}

openvdb::tools::NearestNeighbors neighbours(DilationShape s) {
  switch (s) {
    case DilationShape::Cube:
      return openvdb::tools::NN_FACE_EDGE_VERTEX;
    case DilationShape::FaceEdge:
      return openvdb::tools::NN_FACE_EDGE;
    case DilationShape::Octahedron:
      return openvdb::tools::NN_FACE;
  }
  return openvdb::tools::NN_FACE_EDGE_VERTEX;
}

void dilate(MaskTree& tree, int radius, DilationShape shape) {
  if (radius <= 0 || tree.empty()) return;
  // EXPAND_TILES keeps the result voxelized (no pruning into tiles); the enumeration
  // above handles tiles anyway. OpenVDB threads this with TBB; topology union is
  // order independent, so the result is deterministic.
  openvdb::tools::dilateActiveValues(tree, radius, neighbours(shape), openvdb::tools::EXPAND_TILES);
}

void checkOptions(const OccupancyOptions& o) {
  const std::string file = "SfM points";
  if (o.resolution < 1 || o.resolution > 16384)
    throw InputError(file, "resolution",
                     "expected 1..16384 voxels along the longest side, got " + std::to_string(o.resolution));
  if (o.min_points < 1) throw InputError(file, "min_points", "expected >= 1, got " + std::to_string(o.min_points));
  if (o.upsample < 1 || o.upsample > 64)
    throw InputError(file, "upsample", "expected 1..64, got " + std::to_string(o.upsample));
  // Fine coordinates must stay far inside the key range.
  if (static_cast<long long>(o.resolution) * o.upsample > (1 << 18))
    throw InputError(file, "resolution*upsample", "expected at most 2^18 fine voxels per axis");
  if (!(o.trim_percent >= 0.0 && o.trim_percent < 50.0))
    throw InputError(file, "trim_percent", "expected a percentile in [0, 50)");
  if (o.dilation_radius < 0 || o.dilation_radius > 64)
    throw InputError(file, "dilation_radius", "expected 0..64, got " + std::to_string(o.dilation_radius));
}

// The [p, 100-p] percentile range of one coordinate (nearest rank, no interpolation, so
// the bounds are actual point coordinates).
std::pair<double, double> percentileRange(std::vector<double> v, double p) {
  const std::size_t n = v.size();
  const auto lo_i = static_cast<std::size_t>(std::floor(p / 100.0 * static_cast<double>(n - 1)));
  const auto hi_i = static_cast<std::size_t>(std::ceil((1.0 - p / 100.0) * static_cast<double>(n - 1)));
  std::nth_element(v.begin(), v.begin() + lo_i, v.end());
  const double lo = v[lo_i];
  std::nth_element(v.begin(), v.begin() + hi_i, v.end());
  return {lo, v[hi_i]};
}

}  // namespace

struct OccupancyGrids::Impl {
  OccupancyOptions opts;
  AABB box;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  double coarse_h = 1.0;
  double h = 1.0;
  std::size_t coarse_count = 0;
  MaskTree scene;     // fine scene-occupied voxels
  MaskTree observed;  // dilated observed voxels, accumulated
  VoxelSet scene_keys;
};

OccupancyGrids::OccupancyGrids(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
OccupancyGrids::OccupancyGrids(const OccupancyGrids& o)
    : impl_(std::make_unique<Impl>(*o.impl_)) {}  // MaskTree's copy is deep
OccupancyGrids& OccupancyGrids::operator=(const OccupancyGrids& o) {
  if (this != &o) impl_ = std::make_unique<Impl>(*o.impl_);
  return *this;
}
OccupancyGrids::OccupancyGrids(OccupancyGrids&&) noexcept = default;
OccupancyGrids& OccupancyGrids::operator=(OccupancyGrids&&) noexcept = default;
OccupancyGrids::~OccupancyGrids() = default;

OccupancyGrids OccupancyGrids::fromSfm(std::span<const Eigen::Vector3d> points, const OccupancyOptions& opts) {
  checkOptions(opts);
  const std::string file = "SfM points";
  if (points.empty()) throw InputError(file, "points", "expected at least one point to span the grid");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite()) throw InputError(file, "point " + std::to_string(i), "expected finite coordinates");

  auto impl = std::make_unique<Impl>();
  impl->opts = opts;
  // Box: plain AABB, or per-axis percentiles to drop far outliers that would stretch it.
  if (opts.trim_percent > 0.0) {
    for (int a = 0; a < 3; ++a) {
      std::vector<double> c(points.size());
      for (std::size_t i = 0; i < points.size(); ++i) c[i] = points[i][a];
      const auto [lo, hi] = percentileRange(std::move(c), opts.trim_percent);
      impl->box.min[a] = lo;
      impl->box.max[a] = hi;
    }
  } else {
    for (const auto& p : points) impl->box.extend(p);
  }
  const Eigen::Vector3d size = impl->box.max - impl->box.min;
  const double longest = size.maxCoeff();
  if (!(longest > 0.0) || !std::isfinite(longest))
    throw InputError(file, "points", "expected points spanning a box of positive size");
  impl->origin = impl->box.min;
  impl->coarse_h = longest / opts.resolution;
  impl->h = impl->coarse_h / opts.upsample;

  // Number of coarse voxels per axis: `resolution` on the longest side, enough to cover
  // the others.
  Eigen::Vector3i dims;
  for (int a = 0; a < 3; ++a)
    dims[a] = std::clamp(static_cast<int>(std::ceil(size[a] / impl->coarse_h)), 1, opts.resolution);

  // Count SfM points per coarse voxel in a sparse Int32 tree.
  openvdb::Int32Tree counts(0);
  {
    openvdb::tree::ValueAccessor<openvdb::Int32Tree> acc(counts);
    for (const auto& p : points) {
      if (((p - impl->box.min).array() < 0).any() || ((p - impl->box.max).array() > 0).any())
        continue;  // trimmed outlier
      Coord c;
      for (int a = 0; a < 3; ++a) {
        // Points on the max face belong to the last voxel (the box is closed).
        const double f = std::floor((p[a] - impl->origin[a]) / impl->coarse_h);
        c[a] = std::clamp(static_cast<int>(f), 0, dims[a] - 1);
      }
      acc.setValue(c, acc.getValue(c) + 1);
    }
  }

  // Occupied coarse voxel -> N^3 fine voxels.
  const int n = opts.upsample;
  {
    openvdb::tree::ValueAccessor<MaskTree> acc(impl->scene);
    for (auto it = counts.cbeginValueOn(); it; ++it) {
      // Counts were written voxel by voxel: no tiles in this tree.
      if (*it < opts.min_points) continue;
      ++impl->coarse_count;
      const Coord c = it.getCoord();
      const Coord base(c.x() * n, c.y() * n, c.z() * n);
      for (int dx = 0; dx < n; ++dx)
        for (int dy = 0; dy < n; ++dy)
          for (int dz = 0; dz < n; ++dz) acc.setValueOn(base.offsetBy(dx, dy, dz));
    }
  }
  impl->scene_keys = keysOf(impl->scene);
  return OccupancyGrids(std::move(impl));
}

const OccupancyOptions& OccupancyGrids::options() const { return impl_->opts; }
const AABB& OccupancyGrids::box() const { return impl_->box; }
const Eigen::Vector3d& OccupancyGrids::origin() const { return impl_->origin; }
double OccupancyGrids::voxelSize() const { return impl_->h; }
double OccupancyGrids::coarseVoxelSize() const { return impl_->coarse_h; }

Voxel OccupancyGrids::voxelOf(const Eigen::Vector3d& p) const {
  Voxel v;
  for (int a = 0; a < 3; ++a) {
    const double f = std::floor((p[a] - impl_->origin[a]) / impl_->h);
    // Saturate instead of overflowing; such voxels are not representable and ignored.
    v[a] = static_cast<std::int32_t>(std::clamp(f, -2147483648.0, 2147483647.0));
  }
  return v;
}

Eigen::Vector3d OccupancyGrids::voxelCenter(const Voxel& v) const {
  return impl_->origin + impl_->h * Eigen::Vector3d(v[0] + 0.5, v[1] + 0.5, v[2] + 0.5);
}

std::size_t OccupancyGrids::sceneCount() const { return impl_->scene_keys.size(); }
const VoxelSet& OccupancyGrids::sceneVoxels() const { return impl_->scene_keys; }
bool OccupancyGrids::isSceneOccupied(const Voxel& v) const { return impl_->scene.isValueOn(toCoord(v)); }
std::size_t OccupancyGrids::coarseCount() const { return impl_->coarse_count; }

AABB OccupancyGrids::sceneVoxelBounds() const {
  AABB b;
  if (impl_->scene.empty()) return b;
  CoordBBox cb;
  impl_->scene.evalActiveVoxelBoundingBox(cb);
  for (int a = 0; a < 3; ++a) {
    b.min[a] = impl_->origin[a] + impl_->h * cb.min()[a];
    b.max[a] = impl_->origin[a] + impl_->h * (cb.max()[a] + 1);
  }
  return b;
}

std::size_t OccupancyGrids::addObserved(std::span<const Eigen::Vector3d> points) {
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite())
      throw InputError("SA-Points", "point " + std::to_string(i), "expected finite coordinates");
  MaskTree fresh;
  std::size_t ignored = 0;
  {
    openvdb::tree::ValueAccessor<MaskTree> acc(fresh);
    for (const auto& p : points) {
      const Voxel v = voxelOf(p);
      if (!voxelRepresentable(v)) {
        ++ignored;
        continue;
      }
      acc.setValueOn(toCoord(v));
    }
  }
  // Dilating only the new voxels and taking the union equals dilating everything again:
  // dilation by a kernel distributes over union.
  dilate(fresh, impl_->opts.dilation_radius, impl_->opts.dilation_shape);
  impl_->observed.topologyUnion(fresh);
  return ignored;
}

void OccupancyGrids::clearObserved() { impl_->observed.clear(); }
std::size_t OccupancyGrids::observedCount() const { return impl_->observed.activeVoxelCount(); }
bool OccupancyGrids::isObserved(const Voxel& v) const { return impl_->observed.isValueOn(toCoord(v)); }
VoxelSet OccupancyGrids::observedVoxels() const { return keysOf(impl_->observed); }

VoxelSet OccupancyGrids::observedSceneVoxels() const {
  // Walk the scene keys (block-major, so the accessor's cached leaf is reused) and keep
  // the observed ones: the output is sorted without a sort.
  openvdb::tree::ValueAccessor<const MaskTree> acc(impl_->observed);
  std::vector<VoxelKey> out;
  for (VoxelKey k : impl_->scene_keys.keys())
    if (acc.isValueOn(toCoord(unpackVoxel(k)))) out.push_back(k);
  return VoxelSet::fromSortedKeys(std::move(out));
}

double OccupancyGrids::observedFraction() const {
  if (impl_->scene_keys.empty()) return 0.0;
  return static_cast<double>(observedSceneVoxels().size()) / static_cast<double>(impl_->scene_keys.size());
}

GridMemory OccupancyGrids::memory() const {
  GridMemory m;
  m.scene_vdb = static_cast<std::size_t>(impl_->scene.memUsage());
  m.observed_vdb = static_cast<std::size_t>(impl_->observed.memUsage());
  m.scene_index = impl_->scene_keys.keys().capacity() * sizeof(VoxelKey);
  return m;
}

VoxelSet dilateVoxels(const VoxelSet& voxels, int radius, DilationShape shape) {
  if (radius < 0) throw InputError("dilation", "radius", "expected >= 0, got " + std::to_string(radius));
  if (radius == 0) return voxels;
  MaskTree tree;
  {
    openvdb::tree::ValueAccessor<MaskTree> acc(tree);
    for (VoxelKey k : voxels.keys()) acc.setValueOn(toCoord(unpackVoxel(k)));
  }
  dilate(tree, radius, shape);
  return keysOf(tree);
}

}  // namespace saresgs
