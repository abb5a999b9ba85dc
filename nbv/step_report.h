#pragma once
// One step of an active run as results.json and the run's checkpoint store it: views by
// name. toJson and stepReportFromJson are exact inverses on what they write.
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "geometry/scene/scene.h"
#include "nbv/selection_log.h"
#include "nbv/selection_seconds.h"

namespace saresgs {

// One training phase and the selection after it. The final phase has no selection:
// `selected` is empty and so are the candidate lists.
struct StepReport {
  int views_before = 0;
  double progress_psnr = 0;  // on the progress test views, before selection
  SelectionSeconds seconds;
  std::string selected;
  std::vector<std::string> candidates;                            // what the final scorer saw
  std::vector<double> scores;                                     // their scores
  std::vector<std::string> prefiltered;                           // coverage methods: the kept top N %
  std::vector<double> fisher_scores, new_surface, view_distance;  // hybrid: its evidence
};

nlohmann::json toJson(const StepReport& s);
// Throws InputError naming `source` and the field when a field is missing or mistyped.
StepReport stepReportFromJson(const nlohmann::json& j, const std::string& source, const std::string& field);

// The loop's step record with views named, and back (names are looked up among the train
// views; an unknown name throws InputError naming `source`).
StepReport stepReport(const Scene& scene, const SelectionLog& log);
SelectionLog selectionLog(const Scene& scene, const StepReport& step, const std::string& source);

}  // namespace saresgs
