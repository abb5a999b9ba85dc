// libFuzzer target: a trainer checkpoint (checkpoint.bin, `saresgs train --resume`),
// loaded into a trainer of the tiny scene (fuzz_support.h).
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_fixtures.h"
#include "fuzz/fuzz_support.h"
#include "splat/train/trainer.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saresgs;
  static const std::string path = fuzz::scratchPath("trainer/checkpoint.bin");
  fuzz::writeBytes(path, {reinterpret_cast<const char*>(data), size});
  fuzz::check([&] {
    Trainer t(fuzz::tinyScene(), fuzz::tinyTrainer());
    t.loadCheckpoint(path);
  });
  return 0;
}
