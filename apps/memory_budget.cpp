#include "apps/memory_budget.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "geometry/error.h"

namespace saresgs::apps {

namespace {

std::string gb(double bytes) {
  char buf[32];
  if (bytes >= 1e9)
    std::snprintf(buf, sizeof buf, "%.2f GB", bytes / 1e9);
  else
    std::snprintf(buf, sizeof buf, "%.1f MB", bytes / 1e6);
  return buf;
}

double readNumber(const std::string& path) {
  std::ifstream in(path);
  std::string s;
  if (!(in >> s) || s == "max") return -1;
  try {
    return std::stod(s);
  } catch (...) {
    return -1;
  }
}

}  // namespace

double memoryBudgetBytes(std::optional<double> budget_gb) {
  if (budget_gb) return *budget_gb * 1e9;
  double available = -1;
  std::ifstream in("/proc/meminfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("MemAvailable:", 0) == 0) {
      std::istringstream ls(line.substr(13));
      double kb = 0;
      if (ls >> kb) available = kb * 1024.0;
    }
  const double limit = readNumber("/sys/fs/cgroup/memory.max"), used = readNumber("/sys/fs/cgroup/memory.current");
  if (limit > 0 && used >= 0 && (available < 0 || limit - used < available)) available = limit - used;
  return available > 0 ? available : 1e18;  // unknown: no limit
}

double currentRssBytes() {
  std::ifstream in("/proc/self/statm");
  double size = 0, resident = 0;
  if (!(in >> size >> resident)) return 0;
  return resident * static_cast<double>(::sysconf(_SC_PAGESIZE));
}

std::string applyMemoryBudget(const MemoryEstimate& e, double budget, bool budget_given, std::size_t& max_gaussians) {
  const double start = e.bytesFor(e.initial_gaussians), model = e.modelBytes(e.initial_gaussians);
  const std::string source = budget_given ? "--memory-budget" : "available on this machine";
  if (start > budget) {
    // --downscale 2 quarters the images and the per-pixel buffers.
    const double halved = start - 0.75 * (e.image_bytes + e.buffer_bytes);
    throw InputError("--memory-budget", "memory",
                     "this run needs about " + gb(start) + " before training (images " + gb(e.image_bytes) + " for " +
                         std::to_string(e.views) + " views up to " + std::to_string(e.largest_width) + "x" +
                         std::to_string(e.largest_height) + ", step buffers " + gb(e.buffer_bytes) +
                         ", initial model " + gb(model) + " for " + std::to_string(e.initial_gaussians) +
                         " Gaussians) but the budget is " + gb(budget) + " (" + source +
                         "): use --downscale 2 (about " + gb(halved) + ") or fewer views, or raise --memory-budget");
  }
  std::string line = "memory: about " + gb(start) + " at the start (images " + gb(e.image_bytes) + ", model " +
                     gb(model) + "), budget " + gb(budget) + " (" + source + ")";
  const std::size_t fit = e.gaussiansWithin(budget);
  if (budget_given) {
    // An explicit budget caps the model: the same budget gives the same run.
    if (max_gaussians == 0 || fit < max_gaussians) {
      max_gaussians = fit;
      line += "; the model is capped at " + std::to_string(fit) + " Gaussians to stay within it";
    }
  } else if (max_gaussians == 0 ? fit < 4 * e.initial_gaussians : fit < max_gaussians) {
    // What happens to be free now must not change the numbers of a run: a warning only,
    // when the model could outgrow the machine (uncapped, within a few times its start:
    // 3DGS models grow 3-10x; capped, below its cap).
    line += "\nwarning: the model may grow past what is available (about " + std::to_string(fit) +
            " Gaussians fit); pass --memory-budget GB to cap it, or --max-gaussians";
  }
  return line + "\n";
}

}  // namespace saresgs::apps
