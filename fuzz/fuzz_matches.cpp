// libFuzzer target: a matches file (geometry/lifting/correspondence.h), read with both
// pixel-centre conventions and thinned as the lifting does.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "geometry/lifting/correspondence.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace saresgs;
  static const std::string path = fuzz::scratchPath("matches/matches.txt");
  fuzz::writeBytes(path, {reinterpret_cast<const char*>(data), size});
  fuzz::check([&] {
    const std::vector<Correspondence> m = readMatches(path);
    (void)subsampleByStride(m, 5, 64, 48);
    (void)readMatches(path, MatchesFileOptions{0.0});
  });
  return 0;
}
