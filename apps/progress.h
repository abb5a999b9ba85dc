#pragma once
// A one-line progress display on stderr: stage, count, rate and ETA, redrawn in place
// when stderr is a terminal and printed every ~10 % otherwise (logs stay readable).
#include <chrono>
#include <string>

namespace saresgs::apps {

class Progress {
 public:
  void update(const std::string& stage, int done, int total);

 private:
  std::string stage_;
  std::chrono::steady_clock::time_point start_;
  int last_decile_ = -1;
};

}  // namespace saresgs::apps
