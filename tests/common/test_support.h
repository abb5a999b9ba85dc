#pragma once
// Helpers shared by the geometry tests: a temporary directory per test and a check
// that a call throws InputError naming a file and a field.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <fstream>
#include <random>
#include <string>

#include "geometry/error.h"
#include "geometry/scene/scene.h"
#include "tests/common/ring_scene.h"

namespace saresgs::test {

// A fresh directory under the system temp directory, removed with everything in it.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() / ("saresgs_" + std::string(info ? info->name() : "test") + "_" +
                                                      std::to_string(::getpid()) + "_" + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::string str() const { return path_.string(); }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

inline void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}

inline std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A committed input that a fuzz target once failed on: tests/<room folder>/fuzz_regressions/
// <target>/<name>, given from tests/ (docs/FUZZING.md).
inline std::string fuzzRegression(const std::string& path_in_tests) {
  return std::string(SARESGS_SOURCE_DIR) + "/tests/" + path_in_tests;
}

// Success when `f` throws InputError whose message contains `file` and `field`.
// Any other exception escapes and fails the test.
template <typename F>
::testing::AssertionResult throwsInputError(F&& f, const std::string& file, const std::string& field) {
  try {
    f();
  } catch (const InputError& e) {
    const std::string msg = e.what();
    if (msg.find(file) == std::string::npos || msg.find(field) == std::string::npos)
      return ::testing::AssertionFailure()
             << "message '" << msg << "' lacks file '" << file << "' or field '" << field << "'";
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "no InputError thrown";
}

}  // namespace saresgs::test
