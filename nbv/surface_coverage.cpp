#include "nbv/surface_coverage.h"

#include <algorithm>

#include "geometry/error.h"
#include "geometry/occupancy/candidate_sets.h"

namespace saresgs {

namespace {

OccupancyGrids sceneGrid(const Scene& scene, const OccupancyOptions& o) {
  if (scene.points.empty())
    throw InputError(scene.source, "points",
                     "the hybrid selector (the default --method) needs sparse SfM points for its surface coverage "
                     "(points3D or points3d.ply); give the dataset points, or choose --method fisher or fvs");
  std::vector<Eigen::Vector3d> pts;
  pts.reserve(scene.points.size());
  for (const auto& p : scene.points) pts.push_back(p.xyz);
  return OccupancyGrids::fromSfm(pts, o);
}

}  // namespace

SurfaceCoverage::SurfaceCoverage(const Scene& scene, const SurfaceCoverageOptions& o)
    : scene_(scene),
      opt_(o),
      grids_(std::make_unique<OccupancyGrids>(sceneGrid(scene, o.grid))),
      tracer_(std::make_unique<VisibilityTracer>(*grids_)) {}

SurfaceCoverage::~SurfaceCoverage() = default;

std::size_t SurfaceCoverage::surfaceCount() const { return grids_->sceneCount(); }

const VoxelSet& SurfaceCoverage::visible(int view) const {
  auto it = cache_.find(view);
  if (it == cache_.end())
    it = cache_.emplace(view, tracer_->visibleSet(scene_.views.at(static_cast<std::size_t>(view)).camera, opt_.stride))
             .first;
  return it->second;
}

void SurfaceCoverage::observe(const std::vector<int>& views) {
  for (int v : views) {
    observed_ = setUnion(observed_, visible(v));
    if (std::find(held_.begin(), held_.end(), v) == held_.end()) held_.push_back(v);
  }
}

double SurfaceCoverage::similarity(int a, int b) const {
  if (a == b) return 1.0;
  const std::pair<int, int> key(std::min(a, b), std::max(a, b));
  auto it = similarity_.find(key);
  if (it != similarity_.end()) return it->second;
  const VoxelSet &va = visible(a), &vb = visible(b);
  const std::size_t both = intersectionSize(va, vb), either = va.size() + vb.size() - both;
  const double j = either > 0 ? static_cast<double>(both) / static_cast<double>(either) : 0.0;
  similarity_.emplace(key, j);
  return j;
}

std::vector<double> SurfaceCoverage::facilityGain(const std::vector<int>& candidates,
                                                  const std::vector<int>& population) const {
  std::vector<double> covered(population.size(), 0.0);
  for (std::size_t i = 0; i < population.size(); ++i)
    for (int s : held_) covered[i] = std::max(covered[i], similarity(population[i], s));
  std::vector<double> out;
  out.reserve(candidates.size());
  for (int x : candidates) {
    double gain = 0;  // summed in population order: deterministic
    for (std::size_t i = 0; i < population.size(); ++i)
      gain += std::max(0.0, similarity(population[i], x) - covered[i]);
    out.push_back(gain);
  }
  return out;
}

std::vector<double> SurfaceCoverage::newSurface(const std::vector<int>& candidates) const {
  std::vector<double> out;
  out.reserve(candidates.size());
  const int r = opt_.tolerance;
  for (int c : candidates) {
    if (r <= 0) {
      out.push_back(static_cast<double>(differenceSize(visible(c), observed_)));
      continue;
    }
    std::size_t fresh = 0;
    for (const Voxel& v : visible(c).voxels()) {
      bool near = false;
      for (int dx = -r; dx <= r && !near; ++dx)
        for (int dy = -r; dy <= r && !near; ++dy)
          for (int dz = -r; dz <= r && !near; ++dz) {
            const Voxel n{v[0] + dx, v[1] + dy, v[2] + dz};
            near = voxelRepresentable(n) && observed_.contains(n);
          }
      fresh += !near;
    }
    out.push_back(static_cast<double>(fresh));
  }
  return out;
}

}  // namespace saresgs
