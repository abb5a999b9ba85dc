// libFuzzer target: an ablation grid config (`saresgs ablate --config`), read with
// readAblationGrid and expanded into its jobs as `--list` does.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "nbv/eval/ablation.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saresgs;
  static const std::string path = fuzz::scratchPath("ablation/grid.json");
  fuzz::writeBytes(path, {reinterpret_cast<const char*>(data), size});
  fuzz::check([&] { (void)expandGrid(readAblationGrid(path)); });
  return 0;
}
