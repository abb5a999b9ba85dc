#pragma once
// Occupancy grids of the SA-ResGS prefilter (paper Sec. 3.2, Suppl. A.4):
//   scene grid     voxels of the SfM box that hold >= m SfM points (m = 2 outdoor,
//                  5 indoor) on a coarse grid, each then split into N^3 fine voxels;
//   observed grid  fine voxels that hold SA-Points, dilated by a radius-r kernel and
//                  accumulated over calls (training views add points over time).
// Both are sparse OpenVDB grids (VdbMask, from the OpenVDB module that the first grid
// loads): memory and time follow the occupied voxels, never the volume of the box, and no
// file but the module's includes openvdb.h (~2 s to parse) or loads libopenvdb.
//
// Voxel geometry. The coarse grid starts at the (optionally trimmed) box minimum `origin`;
// its voxel size is the longest box side / `resolution`. Fine voxels have size
// h = coarse size / upsample and the same origin, so coarse voxel c covers the fine voxels
// c*N .. c*N + N-1 on each axis. A world point p lies in fine voxel floor((p - origin)/h);
// "nearest voxel" in the paper's sense is the voxel that contains the point.
#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include "geometry/occupancy/vdb_mask.h"
#include "geometry/occupancy/voxel_set.h"
#include "geometry/scene/scene.h"

namespace saresgs {

struct OccupancyOptions {
  int resolution = 128;       // coarse voxels along the longest side of the box
  int min_points = 2;         // m: a coarse voxel is occupied with >= m SfM points
  int upsample = 2;           // N: each occupied coarse voxel -> N^3 fine voxels
  double trim_percent = 0.0;  // per axis, the box spans the [p, 100-p] percentiles of
                              // the points (outlier trimming); points outside it are
                              // dropped. 0: the plain AABB. In [0, 50).
  int dilation_radius = 2;    // r of the observed-voxel dilation, in fine voxels
  DilationShape dilation_shape = DilationShape::Cube;
};

struct GridMemory {
  std::size_t scene_vdb = 0;     // OpenVDB tree of the fine scene voxels
  std::size_t observed_vdb = 0;  // OpenVDB tree of the observed voxels
  std::size_t scene_index = 0;   // the sorted key array of scene voxels (for the sets)
  std::size_t total() const { return scene_vdb + observed_vdb + scene_index; }
};

// Holds the scene-occupied and observed grids. Copies are deep; const member functions
// are safe to call from several threads; addObserved/clearObserved are not.
class OccupancyGrids {
 public:
  // Builds the scene grid from SfM points. Throws InputError("SfM points", ...) when the
  // options are out of range, a point is not finite, there are no points, or the box has
  // zero size (no voxel size can be derived). A grid with no occupied voxel (no voxel
  // reaches m points) is valid and empty.
  static OccupancyGrids fromSfm(std::span<const Eigen::Vector3d> points, const OccupancyOptions& opts = {});

  OccupancyGrids(const OccupancyGrids&);
  OccupancyGrids& operator=(const OccupancyGrids&);
  OccupancyGrids(OccupancyGrids&&) noexcept;
  OccupancyGrids& operator=(OccupancyGrids&&) noexcept;
  ~OccupancyGrids();

  const OccupancyOptions& options() const;
  const AABB& box() const;                // the (trimmed) SfM box the grid was built on
  const Eigen::Vector3d& origin() const;  // world position of fine voxel (0,0,0)'s corner
  double voxelSize() const;               // fine voxel edge length h
  double coarseVoxelSize() const;
  Voxel voxelOf(const Eigen::Vector3d& p) const;  // floor((p - origin) / h), saturated
  Eigen::Vector3d voxelCenter(const Voxel& v) const;

  // Scene-occupied fine voxels.
  std::size_t sceneCount() const;
  const VoxelSet& sceneVoxels() const;  // sorted keys, computed once at construction
  bool isSceneOccupied(const Voxel& v) const;
  std::size_t coarseCount() const;  // occupied coarse voxels (before upsampling)
  // World box covered by the scene-occupied voxels (empty when there are none). The
  // frustum near/far come from it: it contains every voxel centre.
  AABB sceneVoxelBounds() const;

  // Marks the fine voxels that hold `points`, dilates them and adds them to the observed
  // grid. Dilation distributes over union, so adding points in several calls gives the
  // same grid as one call with all of them. Throws InputError("SA-Points", ...) for a
  // non-finite point; points whose voxel is not representable (more than 2^20 voxels
  // away) are ignored and counted in the return value.
  std::size_t addObserved(std::span<const Eigen::Vector3d> points);
  void clearObserved();
  std::size_t observedCount() const;
  bool isObserved(const Voxel& v) const;
  VoxelSet observedVoxels() const;       // all observed voxels
  VoxelSet observedSceneVoxels() const;  // observed AND scene-occupied
  // |observed AND scene| / |scene|; 0 for an empty scene grid.
  double observedFraction() const;

  GridMemory memory() const;

 private:
  struct Impl;
  explicit OccupancyGrids(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Dilates a voxel set with OpenVDB's topological dilation (`radius` steps of `shape`);
// radius 0 returns the set unchanged. Used by addObserved; exposed for tests and tools.
// Throws InputError("dilation", "radius", ...) for a negative radius.
VoxelSet dilateVoxels(const VoxelSet& voxels, int radius, DilationShape shape = DilationShape::Cube);

}  // namespace saresgs
