// Paired statistics against a hand computation: mean difference, 95 % t interval, win
// rate with ties, the single-seed case (interval undefined, not zero), and the table.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "nbv/eval/ablation.h"
#include "nbv/eval/paired_stats.h"

namespace saresgs {
namespace {

TEST(PairedStats, MeanIntervalAndWinRateByHand) {
  // d = (0.5, 0, 1.5): mean 2/3; s = sqrt(((-1/6)^2 + (-2/3)^2 + (5/6)^2) / 2) = 0.7637626;
  // half width = t(0.975, 2) s / sqrt(3) = 4.3027 x 0.4409586 = 1.8973.
  const PairedDifference d = pairedDifference({24.0, 25.0, 26.5}, {23.5, 25.0, 25.0}, {{20, 21}, {22, 22}, {30, 10}},
                                              {{19, 21}, {23, 22}, {29, 11}});
  EXPECT_EQ(d.n, 3);
  EXPECT_NEAR(d.mean, 2.0 / 3.0, 1e-12);
  ASSERT_TRUE(d.ci_low && d.ci_high);
  EXPECT_NEAR(*d.ci_low, 2.0 / 3.0 - 1.8973, 2e-4);
  EXPECT_NEAR(*d.ci_high, 2.0 / 3.0 + 1.8973, 2e-4);
  // Views: win, tie, loss, tie, win, loss: (1 + 0.5 + 0 + 0.5 + 1 + 0) / 6.
  ASSERT_TRUE(d.win_rate);
  EXPECT_NEAR(*d.win_rate, 3.0 / 6.0, 1e-12);
}

TEST(PairedStats, AllTiedGiveAZeroWidthIntervalAndHalfTheWins) {
  const PairedDifference d = pairedDifference({1, 2}, {1, 2}, {{5}, {6}}, {{5}, {6}});
  EXPECT_EQ(d.mean, 0.0);
  ASSERT_TRUE(d.ci_low && d.ci_high);  // two seeds: defined, and exactly zero width
  EXPECT_EQ(*d.ci_low, 0.0);
  EXPECT_EQ(*d.ci_high, 0.0);
  EXPECT_EQ(*d.win_rate, 0.5);
}

TEST(PairedStats, OneSeedHasNoInterval) {
  const PairedDifference d = pairedDifference({25.0}, {24.25}, {}, {});
  EXPECT_EQ(d.n, 1);
  EXPECT_DOUBLE_EQ(d.mean, 0.75);
  EXPECT_FALSE(d.ci_low.has_value());
  EXPECT_FALSE(d.ci_high.has_value());
  EXPECT_FALSE(d.win_rate.has_value());  // no per-view figures given
  EXPECT_THROW(pairedDifference({1, 2}, {1}), std::invalid_argument);
}

TEST(PairedStats, StudentQuantiles) {
  EXPECT_NEAR(studentT975(1), 12.7062, 1e-4);
  EXPECT_NEAR(studentT975(3), 3.1824, 1e-4);
  EXPECT_NEAR(studentT975(31), 2.0395, 2e-4);   // tables: 2.0395
  EXPECT_NEAR(studentT975(120), 1.9799, 2e-4);  // 1.9799
  EXPECT_NEAR(studentT975(1000000), 1.95996, 1e-4);
  for (int df = 1; df < 200; ++df) EXPECT_GT(studentT975(df), studentT975(df + 1)) << df;
}

// The table pairs runs by seed and says "undefined" for a single seed.
// A grid of one scene "s" with random and fisher at the given seeds, and one finished
// run of it with the loop's PSNR on one test view.
AblationGrid randomAndFisher(std::vector<std::uint64_t> seeds) {
  AblationGrid g;
  g.scenes = {{"s", "x", ""}};
  g.methods = {"random", "fisher"};
  g.seeds = std::move(seeds);
  g.variants = {AblationVariant{}};
  return g;
}
JobResult finishedRun(const std::string& method, std::uint64_t seed, double psnr) {
  JobResult r;
  r.job.scene = "s";
  r.job.method = method;
  r.job.variant = "default";
  r.job.seed = seed;
  r.run.psnr = psnr;
  r.run.views = {{"t0", psnr, 0.5}};
  return r;
}

TEST(PairedStats, TableRowsPerSceneMethodBaselineAndMetric) {
  const AblationGrid g = randomAndFisher({0, 1});
  auto job = [](const std::string& m, std::uint64_t seed, double psnr, double final_psnr) {
    JobResult r = finishedRun(m, seed, psnr);
    r.run.final_fit = FinalFitReport{100, false, final_psnr, 0.8, {{"t0", final_psnr, 0.8}}, {}};
    return r;
  };
  // fisher - random, final fit: seed 0: 27 - 26 = 1, seed 1: 26 - 26 = 0 (a tie).
  std::vector<JobResult> results{job("random", 0, 22, 26), job("random", 1, 22, 26), job("fisher", 0, 23, 27),
                                 job("fisher", 1, 21, 26)};
  Table t = pairedTable(g, results);
  ASSERT_EQ(t.header, (std::vector<std::string>{"scene", "method", "baseline", "metric", "mean_diff", "ci_low",
                                                "ci_high", "n", "win_rate"}));
  ASSERT_EQ(t.rows.size(), 4u);  // fisher vs random, random vs fisher; two metrics each
  EXPECT_EQ(t.rows[0], (std::vector<std::string>{"s", "fisher", "random", "final_fit_psnr", "0.500", "-5.853", "6.853",
                                                 "2", "0.750"}));
  EXPECT_EQ(t.rows[1][3], "psnr");
  EXPECT_EQ(t.rows[1][4], "0.000");
  results.pop_back();  // fisher has one seed left
  t = pairedTable(g, results);
  EXPECT_EQ(t.rows[0][5], "undefined");
  EXPECT_EQ(t.rows[0][6], "undefined");
  EXPECT_EQ(t.rows[0][7], "1");
  EXPECT_NE(t.csv().find("s,fisher,random,final_fit_psnr,1.000,undefined,undefined,1,1.000"), std::string::npos)
      << t.csv();
}

// AUSE (the paper's uncertainty claim) is paired like the PSNRs, as method minus baseline
// (lower is better), over the seeds where both runs have it, with no per-view win rate.
TEST(PairedStats, AuseIsPairedWhereBothRunsHaveIt) {
  const AblationGrid g = randomAndFisher({0, 1, 2});
  auto job = [](const std::string& m, std::uint64_t seed, std::optional<double> ause) {
    JobResult r = finishedRun(m, seed, 20);
    r.run.ause = ause;
    return r;
  };
  // fisher - random: seed 0: 0.30 - 0.35 = -0.05, seed 1: 0.32 - 0.33 = -0.01; seed 2 has
  // no AUSE for fisher (no ground-truth depth), so it is left out.
  const std::vector<JobResult> results{job("random", 0, 0.35), job("random", 1, 0.33), job("random", 2, 0.40),
                                       job("fisher", 0, 0.30), job("fisher", 1, 0.32), job("fisher", 2, std::nullopt)};
  const Table t = pairedTable(g, results);
  const auto row = std::find_if(t.rows.begin(), t.rows.end(), [](const std::vector<std::string>& r) {
    return r[1] == "fisher" && r[2] == "random" && r[3] == "ause";
  });
  ASSERT_NE(row, t.rows.end()) << t.csv();
  EXPECT_EQ((*row)[4], "-0.030");
  EXPECT_EQ((*row)[7], "2");
  EXPECT_EQ((*row)[8], "n/a");
  // The interval: mean -0.03, sd 0.02828, t(1) 12.706: half width 0.254.
  EXPECT_EQ((*row)[5], "-0.284");
  EXPECT_EQ((*row)[6], "0.224");
}

}  // namespace
}  // namespace saresgs
