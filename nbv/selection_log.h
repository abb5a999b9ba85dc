#pragma once
// What one selection step of an active run recorded: the loop keeps it, its checkpoint and
// results.json store it by view name (nbv/step_report.h).
#include <vector>

#include "nbv/selection_seconds.h"

namespace saresgs {

struct SelectionLog {
  int views_before = 0;
  int selected = -1;
  std::vector<int> candidates;   // what the final scorer saw
  std::vector<double> scores;    // their scores
  std::vector<int> prefiltered;  // coverage methods: the kept top N %
  SelectionSeconds seconds;
  double progress_psnr = 0;  // on the progress test views, before selection
  // hybrid: its two kinds of evidence (new_surface: the new surface or the facility gain;
  // view_distance; by hybrid_coverage)
  std::vector<double> fisher_scores, new_surface, view_distance;
};

}  // namespace saresgs
