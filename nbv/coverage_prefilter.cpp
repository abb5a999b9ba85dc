#include "nbv/coverage_prefilter.h"
#include "geometry/enum_names.h"

#include <algorithm>
#include <filesystem>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <numeric>
#include <stdexcept>

#include "geometry/io/json_file.h"
#include "geometry/error.h"
#include "geometry/occupancy/candidate_sets.h"
#include "geometry/occupancy/coverage_score.h"
#include "geometry/occupancy/occupancy_grid.h"

namespace saresgs {

namespace {

class SaPointPrefilter : public CoveragePrefilter {
 public:
  SaPointPrefilter(const Scene& scene, const PrefilterConfig& o) : scene_(scene), config_(o) {
    if (scene.points.empty())
      throw InputError(scene.source, "points", "the coverage prefilter needs sparse SfM points for its occupancy grid");
    std::vector<Eigen::Vector3d> pts;
    pts.reserve(scene.points.size());
    for (const auto& p : scene.points) pts.push_back(p.xyz);
    OccupancyOptions oo;
    oo.resolution = o.resolution;
    oo.min_points = o.min_points;
    oo.upsample = o.upsample;
    if (o.lifting == LiftingSource::kOracle)
      for (int v : scene.train)
        if (!scene.hasDepth(v))
          throw InputError(scene.source, "depth",
                           "the oracle lifting source needs a ground-truth depth map for every train view (view " +
                               std::to_string(v) + " has none)");
    grids_ = std::make_unique<OccupancyGrids>(OccupancyGrids::fromSfm(pts, oo));
    sets_ = std::make_unique<CandidateSetBuilder>(*grids_);
    if (config_.scoring.encoding == CoverageEncoding::Hashed && config_.scoring.table_size == 0)
      config_.scoring.table_size = hashTableSizeFor(grids_->sceneCount());
  }

  PrefilterRegime regime() const override {
    PrefilterRegime r{encodingName(config_.scoring), config_.resolution, config_.min_points, grids_->sceneCount(), {}};
    if (config_.scoring.encoding == CoverageEncoding::Hashed)
      r.hash = hashLoad(grids_->sceneVoxels(), config_.scoring.table_size);
    return r;
  }

  void observe(const std::vector<int>& views, const ViewRenderer& render, const DepthRenderer& depth,
               SelectionSeconds& t) override {
    for (int v : views) {
      const LiftingModule module = config_.lifting == LiftingSource::kFlow    ? flowModule()
                                   : config_.lifting == LiftingSource::kDepth ? depthModule(depth)
                                                                              : depthModule(groundTruthDepth(v));
      const Camera& cam = scene_.views.at(static_cast<std::size_t>(v)).camera;
      const LiftingResult r = liftView(cam, scene_.imageFloat(v), scene_.extent, render, module, lifting_, v);
      t.lifting += r.report.seconds_render + r.report.seconds_correspondence;
      t.triangulation += r.report.seconds_triangulation;
      std::vector<Eigen::Vector3d> p = positions(r.points);
      grids_->addObserved(p);
      observed_points_.insert(observed_points_.end(), p.begin(), p.end());
      report_.add(r.report);
    }
  }

  const OccupancyGrids& grids() const override { return *grids_; }
  const LiftingReport& liftingReport() const override { return report_; }

  std::vector<double> score(const std::vector<int>& candidates, SelectionSeconds& t) override {
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<VoxelSet> sets;
    sets.reserve(candidates.size());
    for (int c : candidates) sets.push_back(candidateSet(c));
    const auto scores = scoreCandidates(grids_->observedSceneVoxels(), sets, grids_->sceneCount(), config_.scoring);
    std::vector<double> out;
    for (const auto& s : scores) out.push_back(criterionValue(s, config_.scoring.criterion));
    t.prefilter += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
  }

  std::string save() const override {
    std::string bytes(observed_points_.size() * sizeof(Eigen::Vector3d), '\0');
    if (!bytes.empty()) std::memcpy(bytes.data(), observed_points_.data(), bytes.size());
    return bytes;
  }
  void load(const std::string& bytes, const std::string& source) override {
    if (bytes.size() % sizeof(Eigen::Vector3d))
      throw InputError(source, "points",
                       "truncated: " + std::to_string(bytes.size()) + " bytes is not a whole number of points");
    observed_points_.resize(bytes.size() / sizeof(Eigen::Vector3d));
    // Vector3d is three packed doubles: the bytes are the points as save() wrote them.
    if (!bytes.empty()) std::memcpy(static_cast<void*>(observed_points_.data()), bytes.data(), bytes.size());
    for (std::size_t i = 0; i < observed_points_.size(); ++i)
      if (!observed_points_[i].allFinite())
        throw InputError(source, "points", "point " + std::to_string(i) + " is NaN or Inf");
    grids_->clearObserved();
    grids_->addObserved(observed_points_);
  }

 private:
  // View v's ground-truth depth map; the lifting asks only for the real view's depth.
  DepthRenderer groundTruthDepth(int v) const {
    return [this, v](const Camera&) { return scene_.depth(v); };
  }

  // A candidate's voxel set depends only on the static scene grid: computed once.
  const VoxelSet& candidateSet(int view) {
    auto it = cache_.find(view);
    if (it != cache_.end()) return it->second;
    const Camera& cam = scene_.views.at(static_cast<std::size_t>(view)).camera;
    return cache_.emplace(view, sets_->build(cam, config_.set, config_.visible_stride)).first->second;
  }

  const Scene& scene_;
  PrefilterConfig config_;
  LiftingOptions lifting_;
  std::unique_ptr<OccupancyGrids> grids_;
  std::unique_ptr<CandidateSetBuilder> sets_;
  std::map<int, VoxelSet> cache_;
  std::vector<Eigen::Vector3d> observed_points_;
  LiftingReport report_;
};

}  // namespace

CandidateSetBuilder::CandidateSetBuilder(const OccupancyGrids& grids) : grids_(grids) {}
CandidateSetBuilder::~CandidateSetBuilder() = default;

void CandidateSetBuilder::prepare(CandidateSetKind kind) const {
  if (kind == CandidateSetKind::kVisible && !tracer_) tracer_ = std::make_unique<VisibilityTracer>(grids_);
}

VoxelSet CandidateSetBuilder::build(const Camera& cam, CandidateSetKind kind, int visible_stride) const {
  if (kind == CandidateSetKind::kFrustum) return frustumSet(grids_, cam);
  prepare(kind);
  return tracer_->visibleSet(cam, visible_stride);
}

const char* toString(CandidateSetKind k) { return k == CandidateSetKind::kFrustum ? "frustum" : "visible"; }

const char* toString(LiftingSource s) { return enumName(s, std::array<const char*, 3>{"flow", "depth", "oracle"}); }

const char* toString(CoverageCriterion c) { return c == CoverageCriterion::Hamming ? "xor" : "new"; }

std::string encodingName(const CoverageScoring& s) {
  if (s.encoding == CoverageEncoding::Exact) return "exact";
  if (s.table_size == 0) return "hash:auto";
  int bits = 0;
  while ((std::size_t{1} << bits) < s.table_size) ++bits;
  return "hash:" + std::to_string(bits);
}

std::vector<int> topFraction(const std::vector<double>& scores, const std::vector<int>& candidates, double fraction) {
  if (scores.size() != candidates.size()) throw std::invalid_argument("topFraction: bad sizes");
  std::vector<std::size_t> order(scores.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const double sa = std::isnan(scores[a]) ? -INFINITY : scores[a], sb = std::isnan(scores[b]) ? -INFINITY : scores[b];
    return sa != sb ? sa > sb : candidates[a] < candidates[b];
  });
  const std::size_t k =
      std::clamp<std::size_t>(static_cast<std::size_t>(std::ceil(fraction * static_cast<double>(scores.size()) - 1e-9)),
                              1, std::max<std::size_t>(1, scores.size()));
  std::vector<int> out;
  for (std::size_t i = 0; i < std::min(k, order.size()); ++i) out.push_back(candidates[order[i]]);
  std::sort(out.begin(), out.end());
  return out;
}

nlohmann::json toJson(const PrefilterRegime& r) {
  nlohmann::json j = {{"encoding", r.encoding},
                      {"resolution", r.resolution},
                      {"min_points", r.min_points},
                      {"scene_voxels", r.scene_voxels}};
  if (r.hash) {
    j["table_size"] = r.hash->table_size;
    j["load_factor"] = r.hash->load;
    j["bits_set"] = r.hash->bits_set;
    j["colliding_voxels"] = r.hash->colliding;
  }
  return j;
}

const char* toString(SceneType t) { return t == SceneType::kIndoor ? "indoor" : "outdoor"; }

void applySceneType(PrefilterConfig& c, SceneType t) {
  c.min_points = t == SceneType::kIndoor ? 5 : 2;
  c.resolution = t == SceneType::kIndoor ? 32 : 64;
}

std::optional<SceneType> sceneTypeOfLayout(std::string_view layout) {
  if (layout == "room360" || layout == "unbalanced" || layout == "tworooms" || layout == "corridor")
    return SceneType::kIndoor;
  if (layout == "object") return SceneType::kOutdoor;
  return std::nullopt;
}

std::optional<SceneType> sceneTypeOfDataset(const std::string& folder) {
  const std::string manifest = folder + "/manifest.json";
  if (folder.empty() || !std::filesystem::exists(manifest)) return std::nullopt;
  const nlohmann::json j = readJsonFile(manifest);
  if (j.is_object() && j.contains("layout") && j["layout"].is_string())
    return sceneTypeOfLayout(j["layout"].get<std::string>());
  return std::nullopt;
}

std::unique_ptr<CoveragePrefilter> makeCoveragePrefilter(const Scene& scene, const PrefilterConfig& config) {
  return std::make_unique<SaPointPrefilter>(scene, config);
}

}  // namespace saresgs
