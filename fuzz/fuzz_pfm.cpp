// libFuzzer target: a PFM depth map or image, read with readPfm.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "geometry/io/pfm.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = saresgs::fuzz::scratchPath("pfm/depth.pfm");
  saresgs::fuzz::checkFile(path, data, size, [](const std::string& p) { (void)saresgs::readPfm(p); });
  return 0;
}
