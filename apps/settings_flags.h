#pragma once
// `saresgs active`'s flags for every setting of the table (nbv/active_settings.h): the
// flag, its help and its checks come from the table's row, the value lands in `settings`.
#include <CLI/CLI.hpp>

#include "nbv/active_settings.h"

namespace saresgs::apps {

void addSettingFlags(CLI::App* sub, ActiveSettings& settings);

}  // namespace saresgs::apps
