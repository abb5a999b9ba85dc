// libFuzzer target: a COLMAP binary model (cameras.bin, images.bin, points3D.bin, packed
// into one input with fuzz_support.h's separator), read, cross-checked and converted to
// saresgs cameras as loadColmapDataset does.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "geometry/io/colmap.h"
#include "geometry/scene/colmap_convert.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saresgs;
  static const std::string dir = fuzz::scratchPath("colmap_binary/model");
  fuzz::writeParts(dir, {"cameras.bin", "images.bin", "points3D.bin"}, fuzz::splitFiles(data, size));
  fuzz::check([&] {
    const ColmapModel model = readColmapBinary(dir);
    validateColmapModel(model, dir);
    for (const auto& [id, cam] : model.cameras) (void)intrinsicsFromColmap(cam, dir + "/cameras.bin");
  });
  return 0;
}
