#pragma once
// Stage times of one view selection (and, summed, of a run), seconds.
#include <nlohmann/json.hpp>

#include <chrono>
#include <string>

namespace saresgs {

struct SelectionSeconds {
  double lifting = 0, triangulation = 0, prefilter = 0, fisher = 0, training = 0;
  double exhaustive_fisher = 0;  // Fisher over all candidates, timed for comparison only
  double coverage = 0;           // the hybrid's visible-surface sets and counts
  // What choosing a view cost: every stage but training (and the comparison timing).
  double selection() const { return lifting + triangulation + prefilter + fisher + coverage; }
  SelectionSeconds& operator+=(const SelectionSeconds& o);
};

// One JSON object with a number per stage, and back; the reader throws InputError(file,
// field.stage) when a stage is missing or not a finite number >= 0 (`coverage` may be
// missing: files written before it was recorded).
nlohmann::json toJson(const SelectionSeconds& s);
SelectionSeconds secondsFrom(const nlohmann::json& j, const std::string& file, const std::string& field);

// Seconds of the steady clock since t0: how the stages above are timed.
inline double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace saresgs
