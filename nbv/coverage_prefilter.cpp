// The coverage prefilter: SA-Points (geometry/lifting) accumulate into the observed
// occupancy grid (geometry/occupancy); each candidate's voxel set (frustum or
// Embree-visible) is compared with it, hashed or exact, by the paper's normalised
// Hamming distance or by the count of newly covered voxels.
#include <chrono>
#include <cstring>
#include <map>
#include <stdexcept>

#include "geometry/error.h"
#include "geometry/occupancy/candidate_sets.h"
#include "geometry/occupancy/coverage_score.h"
#include "geometry/occupancy/occupancy_grid.h"
#include "nbv/active_run.h"

namespace saresgs {

namespace {

class SaPointPrefilter : public CoveragePrefilter {
 public:
  SaPointPrefilter(const Scene& scene, const PrefilterChoice& o) : scene_(scene), choice_(o) {
    if (o.set != "frustum" && o.set != "visible") throw std::invalid_argument("prefilter set '" + o.set + "': expected frustum or visible");
    if (o.lifting != "flow" && o.lifting != "depth") throw std::invalid_argument("lifting '" + o.lifting + "': expected flow or depth");
    opts_ = prefilterOptions(o.encoding, o.score, o.keep_fraction);
    if (scene.points.empty())
      throw InputError(scene.source, "points", "the coverage prefilter needs sparse SfM points for its occupancy grid");
    std::vector<Eigen::Vector3d> pts;
    pts.reserve(scene.points.size());
    for (const auto& p : scene.points) pts.push_back(p.xyz);
    OccupancyOptions oo;
    oo.resolution = o.resolution;
    oo.min_points = o.min_points;
    oo.upsample = o.upsample;
    grids_ = std::make_unique<OccupancyGrids>(OccupancyGrids::fromSfm(pts, oo));
  }

  void observe(const std::vector<int>& views, const ViewRenderer& render, const DepthRenderer& depth,
               SelectionSeconds& t) override {
    const LiftingModule module = choice_.lifting == "depth" ? depthModule(depth) : flowModule();
    for (int v : views) {
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
    const auto scores = scoreCandidates(grids_->observedSceneVoxels(), sets, grids_->sceneCount(), opts_);
    std::vector<double> out;
    for (const auto& s : scores) out.push_back(criterionValue(s, opts_.criterion));
    t.prefilter += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
  }

  std::string save() const override {
    std::string bytes(observed_points_.size() * sizeof(Eigen::Vector3d), '\0');
    if (!bytes.empty()) std::memcpy(bytes.data(), observed_points_.data(), bytes.size());
    return bytes;
  }
  void load(const std::string& bytes) override {
    if (bytes.size() % sizeof(Eigen::Vector3d)) throw InputError("prefilter state", "points", "truncated");
    observed_points_.resize(bytes.size() / sizeof(Eigen::Vector3d));
    // Vector3d is three packed doubles: the bytes are the points as save() wrote them.
    if (!bytes.empty()) std::memcpy(static_cast<void*>(observed_points_.data()), bytes.data(), bytes.size());
    grids_->clearObserved();
    grids_->addObserved(observed_points_);
  }

 private:
  // A candidate's voxel set depends only on the static scene grid: computed once.
  const VoxelSet& candidateSet(int view) {
    auto it = cache_.find(view);
    if (it != cache_.end()) return it->second;
    const Camera& cam = scene_.views.at(static_cast<std::size_t>(view)).camera;
    VoxelSet s;
    if (choice_.set == "frustum") {
      s = frustumSet(*grids_, cam);
    } else {
      if (!tracer_) tracer_ = std::make_unique<VisibilityTracer>(*grids_);
      s = tracer_->visibleSet(cam, choice_.visible_stride);
    }
    return cache_.emplace(view, std::move(s)).first->second;
  }

  const Scene& scene_;
  PrefilterChoice choice_;
  PrefilterOptions opts_;
  LiftingOptions lifting_;
  std::unique_ptr<OccupancyGrids> grids_;
  std::unique_ptr<VisibilityTracer> tracer_;
  std::map<int, VoxelSet> cache_;
  std::vector<Eigen::Vector3d> observed_points_;
  LiftingReport report_;
};

}  // namespace

PrefilterOptions prefilterOptions(const std::string& encoding, const std::string& score, double keep_fraction,
                                  int min_bits, int max_bits) {
  PrefilterOptions o;
  o.keep_percent = 100.0 * keep_fraction;
  if (score == "xor") o.criterion = CoverageCriterion::Hamming;
  else if (score == "new") o.criterion = CoverageCriterion::NewCount;
  else throw std::invalid_argument("prefilter score '" + score + "': expected xor or new");
  if (encoding == "exact") {
    o.encoding = CoverageEncoding::Exact;
  } else if (encoding.rfind("hash:", 0) == 0) {
    int bits = 0;
    try {
      bits = std::stoi(encoding.substr(5));
    } catch (const std::exception&) {
      bits = 0;
    }
    if (bits < min_bits || bits > max_bits)
      throw std::invalid_argument("prefilter encoding '" + encoding + "': expected hash:" + std::to_string(min_bits) +
                                  " .. hash:" + std::to_string(max_bits) + " or exact");
    o.encoding = CoverageEncoding::Hashed;
    o.table_size = std::size_t{1} << bits;
  } else {
    throw std::invalid_argument("prefilter encoding '" + encoding + "': expected hash:K or exact");
  }
  return o;
}

std::unique_ptr<CoveragePrefilter> makeCoveragePrefilter(const Scene& scene, const PrefilterChoice& o, std::uint64_t) {
  return std::make_unique<SaPointPrefilter>(scene, o);
}

}  // namespace saresgs
