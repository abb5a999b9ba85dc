// libFuzzer target: a 3DGS .ply file, read with readGaussiansPly.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "splat/ply.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = saresgs::fuzz::scratchPath("ply/point_cloud.ply");
  saresgs::fuzz::checkFile(path, data, size, [](const std::string& p) { (void)saresgs::readGaussiansPly(p); });
  return 0;
}
