#pragma once
// A one-line progress display on stderr: stage, count, rate and ETA, redrawn in place
// when stderr is a terminal; otherwise (a log, a pipe) printed at every change of `phase`,
// every ~10 % of the count, when the count first reaches its total and at most every
// kLogInterval in between while updates arrive: a log stays readable (an active run's
// final fit, which runs at the loop's full count, once printed a line per iteration) and a
// long stage still shows it is alive.
#include <chrono>
#include <string>

namespace saresgs::apps {

class Progress {
 public:
  // Longest gap between two printed lines when stderr is not a terminal.
  static constexpr std::chrono::seconds kLogInterval{4};

  // `detail` (e.g. "loss 0.031  Gaussians 41k") is printed after the counts.
  // `phase` (e.g. "training", "Fisher") marks a change worth a line of its own in a log.
  void update(const std::string& stage, int done, int total, const std::string& detail = {},
              const std::string& phase = {});

 private:
  std::string stage_;
  std::chrono::steady_clock::time_point start_;
  int last_decile_ = -1;
  int last_done_ = -1;
  std::string last_phase_;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace saresgs::apps
