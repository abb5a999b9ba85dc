// libFuzzer target: a coloured point cloud (the points3d.ply beside a NeRF-synthetic
// folder's transforms), read with readPointsPly.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "geometry/io/point_ply.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = saresgs::fuzz::scratchPath("points_ply/points3d.ply");
  saresgs::fuzz::checkFile(path, data, size, [](const std::string& p) { (void)saresgs::readPointsPly(p); });
  return 0;
}
