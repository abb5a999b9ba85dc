#pragma once
// What the fuzz targets (fuzz/fuzz_*.cpp) and the seed generator (fuzz/make_seeds.cpp)
// share: a scratch folder, several files packed into one input, and the contract every
// reader keeps on any input. The fixed inputs some readers are checked against are in
// fuzz/fuzz_fixtures.h.
//
// The contract: a reader returns, or throws InputError naming a file and a field. Any
// other exception aborts with its message, so libFuzzer records the input; so do a
// sanitizer report, a hang (-timeout), a leak and an allocation over -rss_limit_mb.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace saresgs::fuzz {

// A folder of this process's own under the system temp folder, removed at exit.
const std::string& scratch();
// scratch()/name, with its parent folders created.
std::string scratchPath(const std::string& name);
void writeBytes(const std::string& path, std::string_view bytes);
std::string readBytes(const std::string& path);

// Several files in one input (the three files of a COLMAP model, the two splits of a
// Blender folder) are separated by this line; seeds are written the same way.
inline constexpr std::string_view kNextFile = "\n==saresgs-fuzz-next-file==\n";
std::vector<std::string_view> splitFiles(const std::uint8_t* data, std::size_t size);
std::string joinFiles(const std::vector<std::string>& files);
// Writes part i of `parts` to dir/names[i]; a name without a part is removed, so the
// reader sees it missing.
void writeParts(const std::string& dir, const std::vector<std::string>& names,
                const std::vector<std::string_view>& parts);

// Runs `read` on one input under the contract above. With SARESGS_FUZZ_EXPECT_VALID=1
// in the environment a refusal aborts too: the seed check of the test command.
void check(const std::function<void()>& read);
// The whole of a target that reads one file: writes the input (data, size) to `path` and
// runs `read` on that file under check().
void checkFile(const std::string& path, const std::uint8_t* data, std::size_t size,
               const std::function<void(const std::string& path)>& read);

}  // namespace saresgs::fuzz
