#pragma once
// What a benchmark says of the machine it ran on and of its own process: the CPU's name,
// the load average before and after, peak resident memory and page faults. Every
// `saresgs bench` line carries them, so that a timing is never read without its machine.
#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace saresgs {

// The first "model name" of /proc/cpuinfo; "unknown" where there is none.
std::string cpuModelName();
// The first line of /proc/loadavg ("1.02 0.98 0.91 2/301 4242"); "unknown" where absent.
std::string loadAverage();
// This process's peak resident memory so far (getrusage), in bytes.
double peakRssBytes();
// Page faults (minor + major) of this process so far.
std::uint64_t pageFaults();
// The median (upper median for an even count) of a non-empty sample; 0 for an empty one.
double sampleMedian(std::vector<double> v);

// Counts C++ heap allocations when the program provides a counter (the saresgs binary
// replaces operator new to count them, apps/heap_count.h); nullptr: not counted.
using HeapAllocationCounter = std::uint64_t (*)();

// Adds "cpu", "loadavg_before" (the caller's reading from before the timed work),
// "loadavg_after" and "peak_rss_mb" to a benchmark's line.
void nameMachine(nlohmann::json& line, const std::string& load_before);

}  // namespace saresgs
