// saresgs: the command line. Each subcommand lives in its own file (apps/cmd_*.cpp);
// this file only parses and turns exceptions into a message and a non-zero exit.
#include "apps/cli.h"

#include <exception>
#include <iostream>
#include <string>

#include "apps/commands.h"

namespace saresgs::apps {

int runCli(const std::vector<std::string>& args) {
  CLI::App app{"saresgs: active 3D reconstruction with Gaussian Splatting (SA-ResGS)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "saresgs 0.1.0");
  Action action;
  addInfoCommand(app, action);
  addSceneCommand(app, action);
  addTrainCommand(app, action);
  addBenchCommand(app, action);
  addActiveCommand(app, action);
  addCoverageCommand(app, action);
  addAblateCommand(app, action);
  addReportCommand(app, action);
  // An unknown first word would otherwise read "A subcommand is required".
  std::string names;
  bool known = false;
  for (const CLI::App* s : app.get_subcommands({})) {
    names += (names.empty() ? "" : ", ") + s->get_name();
    known = known || (!args.empty() && s->get_name() == args[0]);
  }
  if (!args.empty() && !args[0].empty() && args[0][0] != '-' && !known) {
    std::cerr << "saresgs: error: unknown subcommand '" << args[0] << "': expected one of " << names << "\n";
    return 2;
  }
  try {
    // CLI11 takes a vector of arguments in reverse order.
    app.parse(std::vector<std::string>(args.rbegin(), args.rend()));
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

}  // namespace saresgs::apps
