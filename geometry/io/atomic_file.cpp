#include "geometry/io/atomic_file.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <unistd.h>

#include "geometry/error.h"

namespace saresgs {

namespace fs = std::filesystem;

void writeStreamAtomic(const std::string& path, const std::function<void(std::ostream&)>& write, bool binary) {
  const fs::path target(path);
  if (target.has_parent_path()) fs::create_directories(target.parent_path());
  const fs::path tmp = target.string() + ".tmp." + std::to_string(::getpid());
  try {
    std::ofstream out(tmp, binary ? std::ios::binary | std::ios::trunc : std::ios::trunc);
    if (!out) throw std::runtime_error(tmp.string() + ": cannot open for writing");
    write(out);
    out.flush();
    if (!out) throw std::runtime_error(path + ": write failed (disk full?)");
  } catch (...) {
    // Nothing half-written is left behind, whatever went wrong.
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
  fs::rename(tmp, target);
}

void writeFileAtomic(const std::string& path, const std::string& bytes) {
  writeStreamAtomic(
      path, [&](std::ostream& o) { o.write(bytes.data(), static_cast<std::streamsize>(bytes.size())); }, true);
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "file", "does not exist or cannot be read");
  std::error_code dir_ec;
  if (fs::is_directory(path, dir_ec)) throw InputError(path, "file", "is a directory, expected a file");
  // A regular file is read in one piece at its size (a stream copy grows by doubling and
  // copies again: three times the file in fresh pages); whatever else (a pipe, a file
  // that changes while read) by chunks to its end.
  std::string out;
  std::error_code ec;
  const auto size = fs::is_regular_file(path, ec) ? fs::file_size(path, ec) : std::uintmax_t{0};
  if (!ec && size > 0 && size < out.max_size()) {
    out.resize(static_cast<std::size_t>(size));
    in.read(out.data(), static_cast<std::streamsize>(out.size()));
    out.resize(static_cast<std::size_t>(in.gcount()));
  }
  char chunk[1 << 16];
  while (in) {
    in.read(chunk, sizeof chunk);
    out.append(chunk, static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad()) throw InputError(path, "file", "read error");
  return out;
}

int removeStaleTemporaries(const std::string& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return 0;
  int removed = 0;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    const auto at = name.rfind(".tmp.");
    if (at == std::string::npos || !e.is_regular_file(ec)) continue;
    const std::string pid = name.substr(at + 5);
    if (pid.empty() || pid.size() > 9 || pid.find_first_not_of("0123456789") != std::string::npos) continue;
    if (std::stol(pid) == ::getpid() || fs::exists("/proc/" + pid, ec)) continue;  // its writer may still finish
    if (fs::remove(e.path(), ec)) ++removed;
  }
  return removed;
}

}  // namespace saresgs
