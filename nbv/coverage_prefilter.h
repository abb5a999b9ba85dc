#pragma once
// The coverage prefilter of SA-ResGS (paper Sec. 3.2): SA-Points lifted from the chosen
// views accumulate into the observed occupancy grid (geometry/occupancy); every candidate
// view's voxel set (frustum or Embree-visible) is compared with it, hashed or exact, by
// the paper's normalised Hamming distance (XOR) or by the count of newly covered voxels;
// the top N % of candidates go on to Fisher scoring.
//
// Options arrive as text at the edges (CLI, ablation grid) and are parsed once, by the
// parse* functions below, into PrefilterConfig; nothing further in is a string.
#include <nlohmann/json.hpp>

#include <memory>
#include <optional>
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
  // Table size 0: chosen when the scene grid is built, the smallest 2^K in the paper's
  // 2^11..2^19 whose load factor (scene voxels / T) is at most 0.5 ("hash:auto"; the
  // paper's robustness to hash size rests on a low load). Its regime is reported
  // (CoveragePrefilter::regime).
  CoverageScoring scoring{CoverageEncoding::Hashed, CoverageCriterion::Hamming, 0};
  double keep_fraction = 0.2;  // top N % kept for Fisher, as a fraction
  int visible_stride = 4;      // pixel stride of the visibility rays
  LiftingSource lifting = LiftingSource::kFlow;
  // Occupancy grid: resolution along the longest side and the SfM points per occupied
  // voxel; the defaults are the outdoor ones (applySceneType: the paper's m = 2 outdoor,
  // m = 5 indoor; the paper gives no resolution).
  int resolution = 64;
  int min_points = 2;
  int upsample = 2;
};

// The paper's per-scene-type SfM point threshold: m = 5 indoors, 2 outdoors. The paper
// gives no grid resolution; at m = 5 our 12k-point rooms leave 336 (room360) and 1840
// (unbalanced) fine voxels occupied at resolution 64 and 8584 / 10304 at 32, so indoor
// scenes use resolution 32 (coarse voxels of about 30 cm in a 10 m room); outdoor keeps
// 64 at m = 2.
enum class SceneType { kIndoor, kOutdoor };
const char* toString(SceneType t);
void applySceneType(PrefilterConfig& c, SceneType t);
// The scene type of a built-in layout (`saresgs scene --layout`): the rooms are indoor,
// the object outdoor; none for an unknown layout.
std::optional<SceneType> sceneTypeOfLayout(std::string_view layout);
// The scene type of a dataset folder written by `saresgs scene` (its manifest.json's
// layout); none for any other folder or an unknown layout.
std::optional<SceneType> sceneTypeOfDataset(const std::string& folder);

// What the prefilter's grid and encoding are: scene-occupied voxels (what is hashed),
// the encoding used ("hash:K" with K resolved, or "exact"), and for a hash its load.
struct PrefilterRegime {
  std::string encoding;
  int resolution = 0, min_points = 0;
  std::size_t scene_voxels = 0;
  std::optional<HashLoad> hash;  // none for exact sets
};

// The options as text (their parsers): nbv/prefilter_options.h.
const char* toString(CandidateSetKind k);
const char* toString(LiftingSource s);
const char* toString(CoverageCriterion c);
std::string encodingName(const CoverageScoring& s);  // "exact" or "hash:K"

// The top-N cut: the candidates in the top `fraction` (at least one) by score, in view
// order; NaN scores rank last and ties go to the lower view index.
std::vector<int> topFraction(const std::vector<double>& scores, const std::vector<int>& candidates, double fraction);

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
  virtual PrefilterRegime regime() const = 0;
  // Serialised observed state, so a resumed run continues with the same grids.
  virtual std::string save() const = 0;
  // `source` names the file in errors (a truncated state, a non-finite point).
  virtual void load(const std::string& bytes, const std::string& source) = 0;
};

// As results.json and coverage.json write it: {encoding, resolution, min_points,
// scene_voxels, and for a hash table_size, load_factor, bits_set, colliding_voxels}.
nlohmann::json toJson(const PrefilterRegime& r);

// Throws InputError when the scene has no sparse points (the occupancy grid needs them),
// or for the oracle source when a train view has no ground-truth depth map.
std::unique_ptr<CoveragePrefilter> makeCoveragePrefilter(const Scene& scene, const PrefilterConfig& config);

}  // namespace saresgs
