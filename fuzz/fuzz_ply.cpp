// libFuzzer target: a 3DGS .ply file, read with readGaussiansPly.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "splat/ply.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saresgs;
  static const std::string path = fuzz::scratchPath("ply/point_cloud.ply");
  fuzz::writeBytes(path, {reinterpret_cast<const char*>(data), size});
  fuzz::check([&] { (void)readGaussiansPly(path); });
  return 0;
}
