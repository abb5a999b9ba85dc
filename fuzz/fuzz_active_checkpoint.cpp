// libFuzzer target: an active run's checkpoint.json (`saresgs active --resume`), resumed
// by a run of the tiny scene (fuzz_support.h). Its trainer companions
// checkpoint.json.trainer.N are valid files for every N a run of tinyActive() can hold,
// so that an accepted checkpoint goes on to resume the trainer; the run is stopped at
// its first progress report, once the checkpoint is loaded.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_fixtures.h"
#include "fuzz/fuzz_support.h"
#include "nbv/active_run.h"

namespace {

struct Resumed {};

std::string checkpoint() {
  using namespace saresgs;
  const std::string path = fuzz::scratchPath("active/checkpoint.json");
  Trainer t(fuzz::tinyScene(), fuzz::tinyTrainer());
  const std::string trainer = fuzz::scratchPath("active/trainer.bin");
  t.saveCheckpoint(trainer);
  const std::string bytes = fuzz::readBytes(trainer);
  for (int n = 0; n <= fuzz::tinyActive().max_views + 1; ++n)
    fuzz::writeBytes(path + ".trainer." + std::to_string(n), bytes);
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saresgs;
  static const std::string path = checkpoint();
  fuzz::writeBytes(path, {reinterpret_cast<const char*>(data), size});
  fuzz::check([&] {
    ActiveRun run(fuzz::tinyScene(), fuzz::tinyActive(), path);
    try {
      (void)run.run([](const ActiveProgress&) { throw Resumed{}; });
    } catch (const Resumed&) {
    }
  });
  return 0;
}
