#pragma once
// A one-line progress display on stderr: stage, count, rate and ETA, redrawn in place
// when stderr is a terminal and printed every ~10 % otherwise (logs stay readable).
#include <chrono>
#include <string>

namespace saresgs::apps {

class Progress {
 public:
  // `detail` (e.g. "loss 0.031  Gaussians 41k") is printed after the counts.
  void update(const std::string& stage, int done, int total, const std::string& detail = {});

 private:
  std::string stage_;
  std::chrono::steady_clock::time_point start_;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace saresgs::apps
