#pragma once
// C++ heap allocations made by this process so far (every operator new, any thread):
// the saresgs binary replaces the global operator new to count them (apps/heap_count.cpp),
// so that `saresgs bench` can report allocations per training step. The count is a
// relaxed atomic increment; nothing else changes.
#include <cstdint>

namespace saresgs::apps {
std::uint64_t heapAllocations();
}
