#pragma once
// Paired comparison of two methods run with common random numbers (same initial model,
// trainer seed and test views per seed index): the mean of the per-seed differences with
// a 95 % Student-t interval over seeds, and the per-test-view win rate.
#include <optional>
#include <vector>

namespace saresgs {

struct PairedDifference {
  int n = 0;                              // seeds with both methods
  double mean = 0;                        // mean of (a - b) over those seeds
  std::optional<double> ci_low, ci_high;  // 95 % t interval; undefined for n < 2
  std::optional<double> win_rate;         // share of (seed, test view) pairs where a > b (ties count half)
};

// a[i], b[i]: one seed's metric for the two methods; views_a[i], views_b[i]: that seed's
// per-test-view metric (the same views in the same order; empty when not known).
PairedDifference pairedDifference(const std::vector<double>& a, const std::vector<double>& b,
                                  const std::vector<std::vector<double>>& views_a = {},
                                  const std::vector<std::vector<double>>& views_b = {});

// The 0.975 quantile of Student's t with `df` degrees of freedom (df >= 1).
double studentT975(int df);

}  // namespace saresgs
