#pragma once
// Coverage analysis without training (`saresgs coverage`): the observed grid from a set
// of views, every other train view scored by the prefilter, the top N %, stage times, and
// a picture of the occupied and observed voxels from above with the cameras' frusta.
#include <memory>
#include <string>
#include <vector>

#include "geometry/image/image.h"
#include "nbv/coverage_prefilter.h"
#include "splat/gaussians.h"

namespace saresgs {

struct CandidateCoverage {
  int view = -1;
  double score = 0;
  int rank = 0;  // 1 = best
  bool kept = false;
};

struct CoverageAnalysis {
  std::vector<int> views;                     // observed
  std::vector<CandidateCoverage> candidates;  // in view order
  std::vector<int> top;                       // kept views, best first
  double observed_fraction = 0;
  std::size_t scene_voxels = 0, observed_voxels = 0;
  LiftingReport lifting;
  double seconds_grid = 0, seconds_lifting = 0, seconds_triangulation = 0, seconds_scoring = 0;
  std::unique_ptr<CoveragePrefilter> prefilter;  // holds the grids for the picture
};

CoverageAnalysis analyzeCoverage(const Scene& scene, const std::vector<int>& views, const PrefilterConfig& config,
                                 const ViewRenderer& render, const DepthRenderer& depth);

// What renders a coverage analysis's extrapolated views: a trained model (in the dataset's
// frame, on its background) when one is given, else the ground truth of a synthetic scene
// rebuilt from the dataset's manifest. `source` says which, for the report. The renderers
// keep the rebuilt scene alive; a model must outlive them.
struct CoverageRenderers {
  ViewRenderer render;
  DepthRenderer depth;
  std::string source;
};
// Throws InputError naming the dataset's manifest, with `how_to_give_a_model` (the front
// end's option), when there is no model and the scene cannot be rebuilt.
CoverageRenderers coverageRenderers(const Scene& scene, const std::string& dataset_path, const Gaussians* model,
                                    const std::string& model_name, const std::string& how_to_give_a_model);

// Occupied voxels (grey), observed ones (blue) from above, with the frusta of the
// observed views (red), the kept candidates (green) and the others (light grey).
Image8 plotCoverage(const Scene& scene, const CoverageAnalysis& a, int size = 800);

}  // namespace saresgs
