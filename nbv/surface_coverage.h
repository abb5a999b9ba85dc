#pragma once
// Occlusion-aware coverage of not-yet-observed surface, for the hybrid selector: the
// scene's surface is the SfM occupancy grid (geometry/occupancy, OpenVDB); a view sees
// the voxels its pixel rays hit first (Embree, VisibilityTracer::visibleSet), so surface
// behind an occluder is not seen; the observed surface is the union of what the chosen
// views see. Camera poses are known for every candidate, so this needs no lifting: what a
// held view saw is a fact of the geometry, not an estimate from the model's renders (the
// SA-Point prefilter's observed grid is the latter).
#include <map>
#include <memory>
#include <vector>

#include "geometry/occupancy/occupancy_grid.h"
#include "geometry/occupancy/voxel_set.h"
#include "geometry/scene/scene.h"

namespace saresgs {

class VisibilityTracer;

struct SurfaceCoverageOptions {
  OccupancyOptions grid;  // scene grid from the SfM points (resolution, points per voxel)
  int stride = 4;         // pixel stride of the visibility rays
  // A seen voxel counts as new only when no observed voxel lies within this many voxels
  // (Chebyshev distance): the sampled rays of one view hit a sample of a surface's
  // voxels, so a second look at the same surface from nearby hits its neighbours; 1
  // absorbs that sampling (0: exact sets).
  int tolerance = 1;
};

class SurfaceCoverage {
 public:
  // Throws InputError naming the scene when it has no sparse points.
  SurfaceCoverage(const Scene& scene, const SurfaceCoverageOptions& o);
  ~SurfaceCoverage();
  SurfaceCoverage(const SurfaceCoverage&) = delete;
  SurfaceCoverage& operator=(const SurfaceCoverage&) = delete;

  // Adds what these views see to the observed surface (a union: order and repeats do not
  // matter).
  void observe(const std::vector<int>& views);
  // Per candidate, the number of surface voxels it sees that no observed view saw (none
  // within `tolerance` voxels).
  std::vector<double> newSurface(const std::vector<int>& candidates) const;
  // Facility location over views (every train view stands for the test views near it):
  // the similarity of two views is the Jaccard index of their visible sets, a view is as
  // covered as its most similar held view, and a candidate's gain is how much adding it
  // raises the sum of that coverage over `population` (the train views):
  //   gain(x) = sum_c max(0, J(c, x) - max_{s held} J(c, s)).
  // Observe the held views first; the similarities are cached.
  std::vector<double> facilityGain(const std::vector<int>& candidates, const std::vector<int>& population) const;
  double similarity(int a, int b) const;  // Jaccard index of the visible sets (1 for a == b)
  // The voxels a view sees (cached per view: cameras do not move).
  const VoxelSet& visible(int view) const;
  std::size_t observedCount() const { return observed_.size(); }
  std::size_t surfaceCount() const;  // scene-occupied voxels

 private:
  const Scene& scene_;
  SurfaceCoverageOptions opt_;
  std::unique_ptr<OccupancyGrids> grids_;
  std::unique_ptr<VisibilityTracer> tracer_;
  mutable std::map<int, VoxelSet> cache_;
  mutable std::map<std::pair<int, int>, double> similarity_;
  VoxelSet observed_;
  std::vector<int> held_;  // the observed views, in the order first observed
};

}  // namespace saresgs
