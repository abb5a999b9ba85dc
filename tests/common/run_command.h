#pragma once
// Runs a shell command line and returns its exit code with stdout and stderr together
// (the CLI tests run the real `saresgs` binary as a user would).
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace saresgs::test {

struct CommandResult {
  int code;
  std::string output;
};

inline CommandResult runCommand(const std::string& command) {
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  if (!p) return {-1, "popen failed"};
  std::string out;
  std::array<char, 4096> buf;
  while (std::size_t n = fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  const int status = pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

}  // namespace saresgs::test
