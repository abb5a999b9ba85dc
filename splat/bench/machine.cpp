#include "splat/bench/machine.h"

#include <nlohmann/json.hpp>
#include <sys/resource.h>

#include <algorithm>
#include <fstream>

namespace saresgs {

std::string cpuModelName() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0) {
      const std::size_t colon = line.find(':');
      return colon == std::string::npos || colon + 2 > line.size() ? line : line.substr(colon + 2);
    }
  return "unknown";
}

std::string loadAverage() {
  std::ifstream in("/proc/loadavg");
  std::string line;
  return std::getline(in, line) ? line : "unknown";
}

double peakRssBytes() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return static_cast<double>(ru.ru_maxrss) * 1024.0;
}

std::uint64_t pageFaults() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return static_cast<std::uint64_t>(ru.ru_minflt + ru.ru_majflt);
}

double sampleMedian(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void nameMachine(nlohmann::json& line, const std::string& load_before) {
  line["peak_rss_mb"] = peakRssBytes() / (1024.0 * 1024.0);
  line["cpu"] = cpuModelName();
  line["loadavg_before"] = load_before;
  line["loadavg_after"] = loadAverage();
}

}  // namespace saresgs
