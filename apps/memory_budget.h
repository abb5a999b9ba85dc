#pragma once
// The memory budget of `saresgs train` and `saresgs active` (--memory-budget GB): stated
// before the run and honoured. A run whose images, buffers and initial model do not fit
// is refused with the estimate (splat/train/memory_estimate.h) and what to change; one
// that fits has its model's growth capped so that it stays within the budget.
#include <cstddef>
#include <optional>
#include <string>

#include "splat/train/memory_estimate.h"

namespace saresgs::apps {

// --memory-budget in bytes when given, else what this machine can give now: MemAvailable
// (/proc/meminfo), or the cgroup's memory.max less its memory.current when that is lower.
double memoryBudgetBytes(std::optional<double> budget_gb);

// Throws InputError naming --memory-budget when `e` with its initial model exceeds
// `budget`. Else, with a budget the user gave, lowers max_gaussians (0: no cap) to what
// fits when that is lower (the same budget, the same run); with the machine's, only warns
// (what is free now must not change a run's numbers). Returns the lines to log.
std::string applyMemoryBudget(const MemoryEstimate& e, double budget, bool budget_given, std::size_t& max_gaussians);

// This process's resident memory now (/proc/self/statm), in bytes; 0 where unknown.
double currentRssBytes();

}  // namespace saresgs::apps
