#include "nbv/eval/paired_stats.h"

#include <cmath>
#include <stdexcept>

namespace saresgs {

double studentT975(int df) {
  if (df < 1) throw std::invalid_argument("studentT975: df must be >= 1");
  // Exact to the printed digits for small df (standard tables)...
  static const double kTable[] = {12.7062, 4.3027, 3.1824, 2.7764, 2.5706, 2.4469, 2.3646, 2.3060, 2.2622, 2.2281,
                                  2.2010,  2.1788, 2.1604, 2.1448, 2.1314, 2.1199, 2.1098, 2.1009, 2.0930, 2.0860,
                                  2.0796,  2.0739, 2.0687, 2.0639, 2.0595, 2.0555, 2.0518, 2.0484, 2.0452, 2.0423};
  if (df <= 30) return kTable[df - 1];
  // ...and the Cornish-Fisher expansion about the normal quantile beyond (error < 1e-4).
  const double z = 1.959963984540054, v = df;
  return z + (z * z * z + z) / (4 * v) + (5 * std::pow(z, 5) + 16 * z * z * z + 3 * z) / (96 * v * v);
}

PairedDifference pairedDifference(const std::vector<double>& a, const std::vector<double>& b,
                                  const std::vector<std::vector<double>>& views_a,
                                  const std::vector<std::vector<double>>& views_b) {
  if (a.size() != b.size()) throw std::invalid_argument("pairedDifference: the two methods have different seed counts");
  PairedDifference r;
  r.n = static_cast<int>(a.size());
  if (r.n == 0) return r;
  std::vector<double> d(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) d[i] = a[i] - b[i];
  for (double x : d) r.mean += x;
  r.mean /= r.n;
  if (r.n >= 2) {
    double ss = 0;
    for (double x : d) ss += (x - r.mean) * (x - r.mean);
    const double half = studentT975(r.n - 1) * std::sqrt(ss / (r.n - 1)) / std::sqrt(static_cast<double>(r.n));
    r.ci_low = r.mean - half;
    r.ci_high = r.mean + half;
  }
  if (!views_a.empty() && views_a.size() == views_b.size()) {
    double wins = 0;
    int total = 0;
    for (std::size_t s = 0; s < views_a.size(); ++s) {
      if (views_a[s].size() != views_b[s].size()) throw std::invalid_argument("pairedDifference: test views differ");
      for (std::size_t v = 0; v < views_a[s].size(); ++v, ++total)
        wins += views_a[s][v] > views_b[s][v] ? 1.0 : views_a[s][v] == views_b[s][v] ? 0.5 : 0.0;
    }
    if (total > 0) r.win_rate = wins / total;
  }
  return r;
}

}  // namespace saresgs
