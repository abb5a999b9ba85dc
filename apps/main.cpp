// saresgs entry point: see apps/cli.cpp.
#include <string>
#include <vector>

#include "apps/cli.h"

int main(int argc, char** argv) { return saresgs::apps::runCli(std::vector<std::string>(argv + 1, argv + argc)); }
