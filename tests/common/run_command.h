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

#ifdef SARESGS_CLI
// The project's command line (the `saresgs` binary that SARESGS_CLI names in test_apps)
// run with `args`.
inline CommandResult runCli(const std::string& args) { return runCommand(std::string(SARESGS_CLI) + " " + args); }
#endif

}  // namespace saresgs::test
