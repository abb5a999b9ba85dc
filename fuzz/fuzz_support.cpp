#include "fuzz/fuzz_support.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "geometry/error.h"

namespace saresgs::fuzz {

namespace fs = std::filesystem;

namespace {

struct ScratchFolder {
  std::string path;
  ScratchFolder() {
    // Memory-backed when the machine has /dev/shm: thousands of small files a second.
    std::error_code ec;
    const fs::path base = fs::is_directory("/dev/shm", ec) && ::access("/dev/shm", W_OK) == 0
                              ? fs::path("/dev/shm")
                              : fs::temp_directory_path();
    path = (base / ("saresgs_fuzz_" + std::to_string(::getpid()))).string();
    fs::remove_all(path, ec);
    fs::create_directories(path);
  }
  ~ScratchFolder() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

bool expectValid() {
  static const bool v = [] {
    const char* e = std::getenv("SARESGS_FUZZ_EXPECT_VALID");
    return e != nullptr && std::string(e) == "1";
  }();
  return v;
}

[[noreturn]] void finding(const std::string& what) {
  std::fprintf(stderr, "saresgs fuzz: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

}  // namespace

const std::string& scratch() {
  static ScratchFolder folder;
  return folder.path;
}

std::string scratchPath(const std::string& name) {
  const fs::path p = fs::path(scratch()) / name;
  fs::create_directories(p.parent_path());
  return p.string();
}

void writeBytes(const std::string& path, std::string_view bytes) {
  // A new file rather than a truncated one: ext4 flushes a truncated-and-rewritten file
  // on close (auto_da_alloc), milliseconds per input.
  std::error_code ec;
  fs::remove(path, ec);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) finding("cannot write the scratch file " + path);
}

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string_view> splitFiles(const std::uint8_t* data, std::size_t size) {
  const std::string_view all(reinterpret_cast<const char*>(data), size);
  std::vector<std::string_view> parts;
  std::size_t start = 0;
  while (true) {
    const std::size_t at = all.find(kNextFile, start);
    if (at == std::string_view::npos) {
      parts.push_back(all.substr(start));
      return parts;
    }
    parts.push_back(all.substr(start, at - start));
    start = at + kNextFile.size();
  }
}

std::string joinFiles(const std::vector<std::string>& files) {
  std::string out;
  for (std::size_t i = 0; i < files.size(); ++i) {
    if (i) out += kNextFile;
    out += files[i];
  }
  return out;
}

void writeParts(const std::string& dir, const std::vector<std::string>& names,
                const std::vector<std::string_view>& parts) {
  fs::create_directories(dir);
  for (std::size_t i = 0; i < names.size(); ++i) {
    const std::string path = (fs::path(dir) / names[i]).string();
    if (i < parts.size()) {
      writeBytes(path, parts[i]);
    } else {
      std::error_code ec;
      fs::remove(path, ec);
    }
  }
}

void check(const std::function<void()>& read) {
  try {
    read();
  } catch (const InputError& e) {
    if (e.file().empty() || e.field().empty())
      finding(std::string("InputError without a file or a field: ") + e.what());
    if (expectValid()) finding(std::string("a seed was refused: ") + e.what());
  } catch (const std::exception& e) {
    finding(std::string("an exception other than InputError (no file and field for the user): ") + e.what());
  } catch (...) {
    finding("an exception that is not a std::exception");
  }
}

void checkFile(const std::string& path, const std::uint8_t* data, std::size_t size,
               const std::function<void(const std::string& path)>& read) {
  writeBytes(path, {reinterpret_cast<const char*>(data), size});
  check([&] { read(path); });
}

}  // namespace saresgs::fuzz
