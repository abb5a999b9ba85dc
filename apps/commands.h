#pragma once
// Each subcommand adds itself to the CLI and, when parsed, sets the action to run.
#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace saresgs::apps {

using Action = std::function<int()>;

void addInfoCommand(CLI::App& app, Action& action);           // apps/cmd_info.cpp
void addSceneCommand(CLI::App& app, Action& action);          // apps/cmd_scene.cpp
void addTrainCommand(CLI::App& app, Action& action);          // apps/cmd_train.cpp
void addBenchCommand(CLI::App& app, Action& action);          // apps/cmd_bench.cpp
void addActiveCommand(CLI::App& app, Action& action);         // apps/cmd_active.cpp
void addCoverageCommand(CLI::App& app, Action& action);       // apps/cmd_coverage.cpp
void addAblateCommand(CLI::App& app, Action& action);         // apps/cmd_ablate.cpp
void addReportCommand(CLI::App& app, Action& action);         // apps/cmd_report.cpp

// Parses `saresgs active` arguments (without the subcommand; --out may be left out) and
// builds the run's options without running anything; throws std::invalid_argument with
// the parser's message on a bad option or value (apps/cmd_active.cpp).
void checkActiveArguments(const std::vector<std::string>& args);

}  // namespace saresgs::apps
