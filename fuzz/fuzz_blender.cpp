// libFuzzer target: a NeRF-synthetic / Blender folder, transforms_train.json and (when the
// input holds a second file) transforms_test.json, beside four small RGBA images
// r_0.png .. r_3.png; loaded with loadBlenderDataset.
#include <cstddef>
#include <cstdint>
#include <filesystem>

#include "fuzz/fuzz_support.h"
#include "geometry/image/image.h"
#include "geometry/scene/scene.h"

namespace {

std::string folder() {
  const std::string dir = saresgs::fuzz::scratchPath("blender/r_0.png");
  for (int i = 0; i < 4; ++i) {
    saresgs::Image8 img(8, 6, 4);
    for (std::size_t p = 0; p < img.data.size(); ++p) img.data[p] = static_cast<std::uint8_t>((p * 29 + i * 7) % 256);
    saresgs::writeImage((std::filesystem::path(dir).parent_path() / ("r_" + std::to_string(i) + ".png")).string(), img);
  }
  return std::filesystem::path(dir).parent_path().string();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saresgs;
  static const std::string dir = folder();
  fuzz::writeParts(dir, {"transforms_train.json", "transforms_test.json"}, fuzz::splitFiles(data, size));
  fuzz::check([&] { (void)loadBlenderDataset(dir); });
  return 0;
}
