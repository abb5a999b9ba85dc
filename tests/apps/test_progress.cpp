// The progress display when stderr is a log (not a terminal, as under CTest): a line at
// each phase change, each tenth of the count and when the count first reaches its total,
// not one per update (an active run's final fit runs at the loop's full count: it once
// printed a line per iteration, 1 600 of them).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "apps/progress.h"

namespace saresgs::apps {
namespace {

// The lines `f` writes to stderr.
template <typename F>
std::vector<std::string> stderrLines(F&& f) {
  std::fflush(stderr);
  char path[] = "/tmp/saresgs_progress_XXXXXX";
  const int fd = ::mkstemp(path);
  const int saved = ::dup(2);
  ::dup2(fd, 2);
  f();
  std::fflush(stderr);
  ::dup2(saved, 2);
  ::close(saved);
  ::close(fd);
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  std::remove(path);
  return lines;
}

TEST(Progress, ALogGetsALinePerPhaseAndTenthNotPerUpdate) {
  ASSERT_FALSE(::isatty(2)) << "run with stderr redirected";
  const std::vector<std::string> lines = stderrLines([] {
    Progress p;
    for (int i = 1; i <= 1000; ++i) p.update("active", i, 1000, "training", "training 4");
    for (int i = 0; i < 2000; ++i) p.update("active", 1000, 1000, "final fit", "final fit 20");
    for (int i = 0; i < 2000; ++i) p.update("active", 1000, 1000, "plain refit", "plain refit 20");
  });
  // training: the first update (a new phase) and one line per tenth (the tenth also reaches
  // the total): 11; each later phase: 1. A stall of kLogInterval may add a line.
  ASSERT_GE(lines.size(), 13u);
  EXPECT_LE(lines.size(), 15u);
  int training = 0, final_fit = 0, refit = 0;
  for (const std::string& l : lines) {
    training += l.find("training") != std::string::npos;
    final_fit += l.find("final fit") != std::string::npos;
    refit += l.find("plain refit") != std::string::npos;
  }
  EXPECT_GE(training, 11);
  EXPECT_GE(final_fit, 1);
  EXPECT_LE(final_fit, 2);
  EXPECT_GE(refit, 1);
  EXPECT_LE(refit, 2);
  EXPECT_NE(lines.front().find("[active] 1/1000"), std::string::npos) << lines.front();
}

}  // namespace
}  // namespace saresgs::apps
