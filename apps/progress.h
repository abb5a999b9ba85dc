#pragma once
// A one-line progress display on stderr: stage, count, rate and ETA, redrawn in place
// when stderr is a terminal; otherwise printed every ~10 % and at least every few seconds
// while updates arrive (logs stay readable and a long stage still shows it is alive).
#include <chrono>
#include <string>

namespace saresgs::apps {

class Progress {
 public:
  // Longest gap between two printed lines when stderr is not a terminal.
  static constexpr std::chrono::seconds kLogInterval{4};

  // `detail` (e.g. "loss 0.031  Gaussians 41k") is printed after the counts.
  void update(const std::string& stage, int done, int total, const std::string& detail = {});

 private:
  std::string stage_;
  std::chrono::steady_clock::time_point start_;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace saresgs::apps
