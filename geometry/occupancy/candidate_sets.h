#pragma once
// Candidate voxel sets of a camera over the scene-occupied voxels (paper Sec. 3.2):
//   frustum set  voxels whose centre lies inside the camera frustum (intrinsics, near/far
//                from the scene bounds). This is the paper's V_cand: visibility ignored.
//   visible set  voxels that rays through sampled pixels hit first, traced with Embree
//                against the scene-occupied voxels as boxes (our addition: occluded
//                voxels behind walls do not count as coverage).
// Both return exact VoxelSets (sorted keys); both are deterministic for any thread count.
// A camera that fails validateCamera (zero/NaN focal, zero size, non-rotation, NaN pose)
// raises InputError("candidate camera", ...); a valid camera that sees no voxel gives an
// empty set.
#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "geometry/camera/camera.h"
#include "geometry/occupancy/occupancy_grid.h"
#include "geometry/occupancy/voxel_set.h"

namespace saresgs {

struct DepthRange {
  double near = 0.0;
  double far = 0.0;
  bool empty() const { return !(far >= near && near > 0.0); }
};

// Near/far along the camera's z axis: the min/max depth of the 8 corners of the box of
// the scene-occupied voxels (the "global bounds from the SfM points" of Suppl. A.4,
// taken at voxel resolution so that every voxel centre is inside the range). Near is
// clamped to a small positive depth (1e-6 of the box diagonal) when the camera is inside
// the box; the range is empty when the box is entirely behind the camera or there are
// no scene voxels.
DepthRange sceneDepthRange(const OccupancyGrids& grids, const Camera& cam);

// Scene-occupied voxels whose centres satisfy cam.inFrustum(centre, near, far). Whole
// 8^3 blocks that lie outside one frustum plane are skipped before the per-voxel test.
VoxelSet frustumSet(const OccupancyGrids& grids, const Camera& cam);
VoxelSet frustumSet(const OccupancyGrids& grids, const Camera& cam, const DepthRange& range);

// Pixel positions sampled with stride s: the centre of each s x s block of the image
// (the last, partial block's centre at the border): s = 1 gives every pixel centre.
// Throws InputError("candidate camera", "pixel_stride", ...) for s < 1.
std::vector<Eigen::Vector2d> samplePixels(const Intrinsics& K, int stride);

// An Embree scene of the scene-occupied voxels as axis-aligned boxes (user geometry,
// one primitive per voxel; primitive i is sceneVoxels().keys()[i]), built once per scene
// grid and queried for any number of cameras. The scene grid does not change during an
// active run, so one tracer serves every selection step. Boxes are placed in voxel
// units relative to the grid's lowest voxel, so their corners are exact in float.
// Queries are const and thread-safe.
class VisibilityTracer {
 public:
  // Copies what it needs from `grids` (keys, origin, voxel size); `grids` may go away.
  // Throws std::runtime_error when Embree fails.
  explicit VisibilityTracer(const OccupancyGrids& grids);
  ~VisibilityTracer();
  VisibilityTracer(const VisibilityTracer&) = delete;
  VisibilityTracer& operator=(const VisibilityTracer&) = delete;

  std::size_t voxelCount() const;
  // Index (into the scene keys) of the first voxel hit by origin + t dir, t >= 0; a ray
  // that starts inside a voxel hits it at t = 0. Ties (a ray through an edge shared by
  // two voxels at the same t) go to the smaller key. -1 on a miss.
  std::int64_t firstHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir) const;
  // firstHit for the ray of each samplePixels(cam.K, stride) position, in that order.
  std::vector<std::int64_t> tracePixels(const Camera& cam, int stride) const;
  // The set of voxels hit first by the sampled rays. Not a subset of the frustum set in
  // general: a voxel at the image border can be hit while its centre projects outside.
  VoxelSet visibleSet(const Camera& cam, int stride = 4) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace saresgs
