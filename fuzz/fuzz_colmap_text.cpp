// libFuzzer target: a COLMAP text model (cameras.txt, images.txt, points3D.txt, packed
// into one input with fuzz_support.h's separator), read, cross-checked and converted to
// saresgs cameras as loadColmapDataset does.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_colmap.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string dir = saresgs::fuzz::scratchPath("colmap_text/model");
  saresgs::fuzz::checkColmapModel(dir, {"cameras.txt", "images.txt", "points3D.txt"}, saresgs::readColmapText, data,
                                  size);
  return 0;
}
