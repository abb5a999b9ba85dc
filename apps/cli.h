#pragma once
// The whole `saresgs` command line as a function, so that a subcommand can run another
// one in-process (the ablation runner runs `saresgs active` jobs this way).
#include <string>
#include <vector>

namespace saresgs::apps {

// Parses `args` (without the program name), runs the chosen subcommand and returns its
// exit code; errors are printed on stderr and give a non-zero code, as from main().
int runCli(const std::vector<std::string>& args);

}  // namespace saresgs::apps
