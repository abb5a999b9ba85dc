#pragma once
// Named sizes of an active run. `paper`: the paper's protocol (100 iterations per view
// held, 20 000 in all, 3DGS's schedule). `quick`: the same protocol at a quarter of the
// schedule, for a first result on two cores (preset.cpp says how it was sized).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "nbv/active_options.h"

namespace saresgs {

enum class Preset { kPaper, kQuick };

Preset parsePreset(std::string_view text);  // paper | quick; std::invalid_argument otherwise
const char* toString(Preset p);

// The options of a preset (method, seed and everything a caller overrides left at their
// defaults).
ActiveOptions presetOptions(Preset p);

}  // namespace saresgs
