#pragma once
// Hash vs exact occupancy: how far each cheap prefilter variant's candidate ranking is
// from the reference (exact encoding of the Embree-visible sets, same score), and what it
// costs. Observed states follow the active protocol's start (train index 0 + 3 farthest
// views), then random additions up to each requested view count; SA-Points are lifted
// against the given renderers (ground truth in `saresgs ablate`).
#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "geometry/lifting/sa_points.h"
#include "geometry/scene/scene.h"
#include "nbv/coverage_prefilter.h"

namespace saresgs {

// What a sweep covers; parsed from the ablation grid's "sweep" object.
struct SweepSpec {
  std::vector<std::string> scenes;
  std::vector<int> view_counts = {4, 8, 12};                    // observed states: initial views, then random additions
  std::vector<CoverageScoring> encodings = defaultEncodings();  // their criteria are ignored
  std::vector<CandidateSetKind> sets = {CandidateSetKind::kFrustum, CandidateSetKind::kVisible};
  std::vector<CoverageCriterion> scores = {CoverageCriterion::Hamming, CoverageCriterion::NewCount};
  LiftingSource lifting = LiftingSource::kFlow;
  double keep_fraction = 0.2;
  int timing_repeats = 5;  // scoring is timed as the median of this many repeats

  static std::vector<CoverageScoring> defaultEncodings();  // hash:11 .. hash:19, exact
};
// The sweep's encodings may go beyond the active loop's 2^11..2^19.
inline constexpr int kSweepMinHashBits = 2, kSweepMaxHashBits = 30;

struct SweepRow {
  std::string set, encoding, score;
  int views = 0;  // observed views in this state
  int candidates = 0;
  double overlap = 0;          // |top N % (variant) n top N % (reference)| / |top N % (reference)|
  double kendall_tau = 0;      // tau-b between the variant's and the reference's scores
  double seconds_scoring = 0;  // encode + compare all candidates (median of repeats)
  double seconds_sets = 0;     // building the candidates' voxel sets (no cache)
  double load = 0;             // hash: scene-occupied voxels / table size (0 for exact sets)
};

// One sweep job's result file (sweep.json).
struct SweepReport {
  std::string scene, dataset, lifting, reference;
  std::vector<SweepRow> rows;
  // The occupancy grid swept (the scene type's, from the dataset's layout): scene type
  // ("" when unknown: the outdoor defaults), resolution, SfM points per voxel, and the
  // scene-occupied voxels every hash encodes. Absent from older sweep.json files (0).
  std::string scene_type;
  int resolution = 0, min_points = 0;
  std::size_t scene_voxels = 0;
};
nlohmann::json toJson(const SweepReport& r);
// Throws InputError naming `source` and the field.
SweepReport sweepReportFromJson(const nlohmann::json& j, const std::string& source);

// `grid` gives the occupancy grid and ray settings (resolution, min_points, upsample,
// visible_stride; its lifting and scoring are the spec's); `regime`, if given, receives the
// grid's (exact) regime: resolution, min_points, scene voxels.
std::vector<SweepRow> prefilterSweep(const Scene& scene, const SweepSpec& spec, const ViewRenderer& render,
                                     const DepthRenderer& depth, std::uint64_t seed = 0,
                                     const PrefilterConfig& grid = {}, PrefilterRegime* regime = nullptr);

// Kendall's tau-b of two score vectors of equal length (ties counted as in tau-b); 1 for
// fewer than two items or when either vector is constant and the other is too.
double kendallTauB(const std::vector<double>& a, const std::vector<double>& b);

// |top(a) n top(b)| / |top(b)| with top = topFraction's choice (ties to the lower index).
double topOverlap(const std::vector<double>& a, const std::vector<double>& b, double fraction);

}  // namespace saresgs
