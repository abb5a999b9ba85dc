// saresgs: the command line. Each subcommand lives in its own file (apps/cmd_*.cpp);
// this file only parses and turns exceptions into a message and a non-zero exit.
#include <exception>
#include <iostream>

#include "apps/commands.h"

int main(int argc, char** argv) {
  CLI::App app{"saresgs: active 3D reconstruction with Gaussian Splatting (SA-ResGS)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "saresgs 0.1.0");
  saresgs::apps::Action action;
  saresgs::apps::addInfoCommand(app, action);
  saresgs::apps::addSceneCommand(app, action);
  saresgs::apps::addTrainCommand(app, action);
  saresgs::apps::addBenchCommand(app, action);
  saresgs::apps::addActiveCommand(app, action);
  saresgs::apps::addCoverageCommand(app, action);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    return action ? action() : 0;
  } catch (const std::exception& e) {
    std::cerr << "saresgs: error: " << e.what() << "\n";
    return 1;
  }
}
