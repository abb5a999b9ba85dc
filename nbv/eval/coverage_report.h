#pragma once
// Coverage analysis without training (`saresgs coverage`): the observed grid from a set
// of views, every other train view scored by the prefilter, the top N %, stage times, and
// a picture of the occupied and observed voxels from above with the cameras' frusta.
#include <vector>

#include "geometry/image/image.h"
#include "nbv/coverage_prefilter.h"

namespace saresgs {

struct CandidateCoverage {
  int view = -1;
  double score = 0;
  int rank = 0;  // 1 = best
  bool kept = false;
};

struct CoverageAnalysis {
  std::vector<int> views;  // observed
  std::vector<CandidateCoverage> candidates;  // in view order
  std::vector<int> top;    // kept views, best first
  double observed_fraction = 0;
  std::size_t scene_voxels = 0, observed_voxels = 0;
  LiftingReport lifting;
  double seconds_grid = 0, seconds_lifting = 0, seconds_triangulation = 0, seconds_scoring = 0;
  std::unique_ptr<CoveragePrefilter> prefilter;  // holds the grids for the picture
};

CoverageAnalysis analyzeCoverage(const Scene& scene, const std::vector<int>& views, const PrefilterConfig& config,
                                 const ViewRenderer& render, const DepthRenderer& depth);

// Occupied voxels (grey), observed ones (blue) from above, with the frusta of the
// observed views (red), the kept candidates (green) and the others (light grey).
Image8 plotCoverage(const Scene& scene, const CoverageAnalysis& a, int size = 800);

}  // namespace saresgs
