#pragma once
// Outputs are written to a temporary name beside the target and renamed, so an
// interrupted program never leaves a half-written file where a good one was.
#include <functional>
#include <iosfwd>
#include <string>

namespace saresgs {

void writeFileAtomic(const std::string& path, const std::string& bytes);
// Calls `write` with a stream on a temporary file, then renames it to `path`.
// Throws std::runtime_error naming the file when the stream fails.
void writeStreamAtomic(const std::string& path, const std::function<void(std::ostream&)>& write, bool binary = false);
// Removes the temporaries ("<target>.tmp.<pid>") that a killed writer left in `dir`,
// those whose process is gone; a live writer's are kept. Returns how many were removed.
int removeStaleTemporaries(const std::string& dir);
// Reads a whole file; throws InputError naming the file when it is missing.
std::string readFile(const std::string& path);

}  // namespace saresgs
