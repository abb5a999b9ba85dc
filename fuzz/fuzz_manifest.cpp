// libFuzzer target: the manifest.json of a synthetic dataset, read as loadColmapDataset
// reads it (background, split) and as syntheticOptionsFromManifest reads it (the options
// that rebuild the scene), beside the tiny dataset's COLMAP model and images.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_fixtures.h"
#include "fuzz/fuzz_support.h"
#include "geometry/scene/scene.h"
#include "geometry/synth/from_manifest.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saresgs;
  static const std::string& dir = fuzz::tinyDataset();
  fuzz::writeBytes(dir + "/manifest.json", {reinterpret_cast<const char*>(data), size});
  fuzz::check([&] {
    (void)loadColmapDataset(dir);
    (void)syntheticOptionsFromManifest(dir);
  });
  return 0;
}
