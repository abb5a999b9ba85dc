#pragma once
// Stage times of one view selection (and, summed, of a run), seconds.
#include <nlohmann/json.hpp>

namespace saresgs {

struct SelectionSeconds {
  double lifting = 0, triangulation = 0, prefilter = 0, fisher = 0, training = 0;
  double exhaustive_fisher = 0;  // Fisher over all candidates, timed for comparison only
  // What choosing a view cost: every stage but training (and the comparison timing).
  double selection() const { return lifting + triangulation + prefilter + fisher; }
  SelectionSeconds& operator+=(const SelectionSeconds& o);
};

// One JSON object with a number per stage, and back; the reader throws
// nlohmann::json::exception when a stage is missing or not a number.
nlohmann::json toJson(const SelectionSeconds& s);
SelectionSeconds secondsFrom(const nlohmann::json& j);

}  // namespace saresgs
