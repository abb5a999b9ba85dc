// libFuzzer target: a COLMAP binary model (cameras.bin, images.bin, points3D.bin, packed
// into one input with fuzz_support.h's separator), read, cross-checked and converted to
// saresgs cameras as loadColmapDataset does.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_colmap.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string dir = saresgs::fuzz::scratchPath("colmap_binary/model");
  saresgs::fuzz::checkColmapModel(dir, {"cameras.bin", "images.bin", "points3D.bin"}, saresgs::readColmapBinary, data,
                                  size);
  return 0;
}
