#pragma once
// The coverage prefilter of SA-ResGS (paper Sec. 3.2): SA-Points lifted from the chosen
// views accumulate into the observed occupancy grid (geometry/occupancy); every candidate
// view's voxel set (frustum or Embree-visible) is compared with it, hashed or exact, by
// the paper's normalised Hamming distance (XOR) or by the count of newly covered voxels;
// the top N % of candidates go on to Fisher scoring.
//
// Options arrive as text at the edges (CLI, ablation grid) and are parsed once, by the
// parse* functions below, into PrefilterConfig; nothing further in is a string.
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "geometry/lifting/sa_points.h"
#include "geometry/occupancy/coverage_score.h"
#include "geometry/scene/scene.h"
#include "nbv/selection_seconds.h"

namespace saresgs {

class OccupancyGrids;    // geometry/occupancy/occupancy_grid.h
class VisibilityTracer;  // geometry/occupancy/candidate_sets.h

enum class CandidateSetKind { kFrustum, kVisible };
// Where SA-Points come from: DIS flow + epipolar refinement on the model's renders (the
// paper); the depth the caller supplies (in an active run, the trainer's rendered depth);
// or the dataset's ground-truth depth maps (perfect SA-Points: the upper bound of the
// idea, for synthetic data that has them).
enum class LiftingSource { kFlow, kDepth, kOracle };

struct PrefilterConfig {
  CandidateSetKind set = CandidateSetKind::kFrustum;
  CoverageScoring scoring{CoverageEncoding::Hashed, CoverageCriterion::Hamming, std::size_t{1} << 13};
  double keep_fraction = 0.2;  // top N % kept for Fisher, as a fraction
  int visible_stride = 4;      // pixel stride of the visibility rays
  LiftingSource lifting = LiftingSource::kFlow;
  // Occupancy grid: resolution along the longest side and the SfM points per occupied
  // voxel. The paper's m = 5 (indoor) at 128 leaves a 12k-point SfM cloud almost empty,
  // so the default is sized for sparse clouds (see third_party_notes/openvdb.md).
  int resolution = 64;
  int min_points = 2;
  int upsample = 2;
};

// Parsers of the textual options; each throws std::invalid_argument naming the value and
// what was expected. An encoding is "exact" or "hash:K" with K in [min_bits, max_bits]
// (the active loop takes the paper's 2^11..2^19; the sweep goes beyond); it sets the
// encoding and table size of `scoring` and leaves its criterion alone.
CandidateSetKind parseCandidateSet(std::string_view text);        // frustum | visible
LiftingSource parseLiftingSource(std::string_view text);          // flow | depth | oracle
CoverageCriterion parseCoverageCriterion(std::string_view text);  // xor | new
void parseCoverageEncoding(std::string_view text, CoverageScoring& scoring, int min_bits = 11, int max_bits = 19);
const char* toString(CandidateSetKind k);
const char* toString(LiftingSource s);
const char* toString(CoverageCriterion c);
std::string encodingName(const CoverageScoring& s);  // "exact" or "hash:K"

// The top-N cut: the candidates in the top `fraction` (at least one) by score, in view
// order; NaN scores rank last and ties go to the lower view index.
std::vector<int> topFraction(const std::vector<double>& scores, const std::vector<int>& candidates,
                             double fraction);

// Builds candidate voxel sets of one kind on the static scene grid; the Embree tracer is
// made on first use of the visible kind.
class CandidateSetBuilder {
 public:
  explicit CandidateSetBuilder(const OccupancyGrids& grids);
  ~CandidateSetBuilder();
  VoxelSet build(const Camera& cam, CandidateSetKind kind, int visible_stride) const;
  // Makes what `kind` needs now (the tracer), so that build() times only the set.
  void prepare(CandidateSetKind kind) const;

 private:
  const OccupancyGrids& grids_;
  mutable std::unique_ptr<VisibilityTracer> tracer_;
};

// The prefilter of the coverage methods: builds its state from the scene, learns what the
// chosen views observe (SA-Points lifted against `render`: the trainer's renders in an
// active run, ground-truth renders in the coverage tool), and scores candidates (higher
// = more new coverage).
class CoveragePrefilter {
 public:
  virtual ~CoveragePrefilter() = default;
  // `depth` serves the `depth` lifting source (the renderer's own depth for the real view).
  virtual void observe(const std::vector<int>& new_views, const ViewRenderer& render, const DepthRenderer& depth,
                       SelectionSeconds& t) = 0;
  virtual std::vector<double> score(const std::vector<int>& candidates, SelectionSeconds& t) = 0;
  virtual const OccupancyGrids& grids() const = 0;
  virtual const LiftingReport& liftingReport() const = 0;  // summed over observed views
  // Serialised observed state, so a resumed run continues with the same grids.
  virtual std::string save() const = 0;
  // `source` names the file in errors (a truncated state, a non-finite point).
  virtual void load(const std::string& bytes, const std::string& source) = 0;
};

// Throws InputError when the scene has no sparse points (the occupancy grid needs them),
// or for the oracle source when a train view has no ground-truth depth map.
std::unique_ptr<CoveragePrefilter> makeCoveragePrefilter(const Scene& scene, const PrefilterConfig& config);

}  // namespace saresgs
