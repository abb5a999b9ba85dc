// libFuzzer target: a PFM depth map or image, read with readPfm.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "geometry/io/pfm.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saresgs;
  static const std::string path = fuzz::scratchPath("pfm/depth.pfm");
  fuzz::writeBytes(path, {reinterpret_cast<const char*>(data), size});
  fuzz::check([&] { (void)readPfm(path); });
  return 0;
}
