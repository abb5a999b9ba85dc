// The grids' geometry and checks; their trees are VdbMasks (the OpenVDB module).
#include "geometry/occupancy/occupancy_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "geometry/error.h"

namespace saresgs {

namespace {

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
  VdbMask scene;     // fine scene-occupied voxels
  VdbMask observed;  // dilated observed voxels, accumulated
  VoxelSet scene_keys;
};

OccupancyGrids::OccupancyGrids(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
OccupancyGrids::OccupancyGrids(const OccupancyGrids& o)
    : impl_(std::make_unique<Impl>(*o.impl_)) {}  // VdbMask's copy is deep
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

  // Count SfM points per coarse voxel: sort the coarse voxels' keys and count the runs.
  std::vector<VoxelKey> coarse;
  coarse.reserve(points.size());
  for (const auto& p : points) {
    if (((p - impl->box.min).array() < 0).any() || ((p - impl->box.max).array() > 0).any())
      continue;  // trimmed outlier
    Voxel c;
    for (int a = 0; a < 3; ++a) {
      // Points on the max face belong to the last voxel (the box is closed).
      const double f = std::floor((p[a] - impl->origin[a]) / impl->coarse_h);
      c[a] = std::clamp(static_cast<int>(f), 0, dims[a] - 1);
    }
    coarse.push_back(packVoxel(c));  // 0 <= c < 16384: representable
  }
  std::sort(coarse.begin(), coarse.end());

  // Occupied coarse voxel -> N^3 fine voxels, handed to the tree in batches.
  const int n = opts.upsample;
  std::vector<Voxel> fine;
  const std::size_t batch = std::size_t{1} << 16;
  for (std::size_t i = 0; i < coarse.size();) {
    std::size_t j = i;
    while (j < coarse.size() && coarse[j] == coarse[i]) ++j;
    if (j - i >= static_cast<std::size_t>(opts.min_points)) {
      ++impl->coarse_count;
      const Voxel c = unpackVoxel(coarse[i]);
      for (int dx = 0; dx < n; ++dx)
        for (int dy = 0; dy < n; ++dy)
          for (int dz = 0; dz < n; ++dz) fine.push_back({c[0] * n + dx, c[1] * n + dy, c[2] * n + dz});
      if (fine.size() >= batch) {
        impl->scene.setOn(fine);
        fine.clear();
      }
    }
    i = j;
  }
  impl->scene.setOn(fine);
  impl->scene_keys = impl->scene.keys();
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
bool OccupancyGrids::isSceneOccupied(const Voxel& v) const { return impl_->scene.isOn(v); }
std::size_t OccupancyGrids::coarseCount() const { return impl_->coarse_count; }

AABB OccupancyGrids::sceneVoxelBounds() const {
  AABB b;
  Voxel lo, hi;
  if (!impl_->scene.bounds(lo, hi)) return b;
  for (int a = 0; a < 3; ++a) {
    b.min[a] = impl_->origin[a] + impl_->h * lo[a];
    b.max[a] = impl_->origin[a] + impl_->h * (hi[a] + 1);
  }
  return b;
}

std::size_t OccupancyGrids::addObserved(std::span<const Eigen::Vector3d> points) {
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite())
      throw InputError("SA-Points", "point " + std::to_string(i), "expected finite coordinates");
  std::vector<Voxel> voxels;
  voxels.reserve(points.size());
  std::size_t ignored = 0;
  for (const auto& p : points) {
    const Voxel v = voxelOf(p);
    if (!voxelRepresentable(v)) {
      ++ignored;
      continue;
    }
    voxels.push_back(v);
  }
  VdbMask fresh;
  fresh.setOn(voxels);
  // Dilating only the new voxels and taking the union equals dilating everything again:
  // dilation by a kernel distributes over union.
  fresh.dilate(impl_->opts.dilation_radius, impl_->opts.dilation_shape);
  impl_->observed.unite(fresh);
  return ignored;
}

void OccupancyGrids::clearObserved() { impl_->observed.clear(); }
std::size_t OccupancyGrids::observedCount() const { return impl_->observed.activeCount(); }
bool OccupancyGrids::isObserved(const Voxel& v) const { return impl_->observed.isOn(v); }
VoxelSet OccupancyGrids::observedVoxels() const { return impl_->observed.keys(); }

VoxelSet OccupancyGrids::observedSceneVoxels() const {
  // The scene keys (block-major, so the module's accessor reuses its cached leaf) that
  // are observed: sorted without a sort.
  return impl_->observed.filter(impl_->scene_keys);
}

double OccupancyGrids::observedFraction() const {
  if (impl_->scene_keys.empty()) return 0.0;
  return static_cast<double>(observedSceneVoxels().size()) / static_cast<double>(impl_->scene_keys.size());
}

GridMemory OccupancyGrids::memory() const {
  GridMemory m;
  m.scene_vdb = impl_->scene.memUsage();
  m.observed_vdb = impl_->observed.memUsage();
  m.scene_index = impl_->scene_keys.keys().capacity() * sizeof(VoxelKey);
  return m;
}

VoxelSet dilateVoxels(const VoxelSet& voxels, int radius, DilationShape shape) {
  if (radius < 0) throw InputError("dilation", "radius", "expected >= 0, got " + std::to_string(radius));
  if (radius == 0) return voxels;
  VdbMask tree;
  tree.setOn(voxels.voxels());
  tree.dilate(radius, shape);
  return tree.keys();
}

}  // namespace saresgs
