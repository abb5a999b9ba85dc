// libFuzzer target: a COLMAP text model (cameras.txt, images.txt, points3D.txt, packed
// into one input with fuzz_support.h's separator), read, cross-checked and converted to
// saresgs cameras as loadColmapDataset does.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "geometry/io/colmap.h"
#include "geometry/scene/colmap_convert.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saresgs;
  static const std::string dir = fuzz::scratchPath("colmap_text/model");
  fuzz::writeParts(dir, {"cameras.txt", "images.txt", "points3D.txt"}, fuzz::splitFiles(data, size));
  fuzz::check([&] {
    const ColmapModel model = readColmapText(dir);
    validateColmapModel(model, dir);
    for (const auto& [id, cam] : model.cameras) (void)intrinsicsFromColmap(cam, dir + "/cameras.txt");
  });
  return 0;
}
