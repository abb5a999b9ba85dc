#pragma once
// The prefilter's parts timed on a room360 scene with simulated SfM points
// (`saresgs bench occupancy`): the scene grid's build, the observed dilation, the Embree
// tracer, frustum against visible candidate sets, exact against hashed scoring, and the
// grids' memory. One JSON line, with the machine and its load named.
#include <nlohmann/json_fwd.hpp>

#include <cstddef>
#include <cstdint>

namespace saresgs {

struct OccupancyBenchOptions {
  int width = 256, height = 192;  // the synthetic views (their depth maps give SA-Points)
  std::size_t points = 12000;     // simulated SfM points at most
  int resolution = 128;           // coarse voxels along the box's longest side
  int upsample = 2;
  int min_points = 2;
  int threads = 0;  // 0: every core; else caps every TBB pool of the process while it runs
  std::uint64_t seed = 5;
};

nlohmann::json benchOccupancy(const OccupancyBenchOptions& o);

}  // namespace saresgs
