#include <gtest/gtest.h>

#include <random>

#include "common/test_support.h"
#include "geometry/lifting/correspondence.h"

using namespace saresgs;
using saresgs::test::TempDir;
using saresgs::test::throwsInputError;
using saresgs::test::writeBytes;

TEST(MatchesFile, RoundTripIsExact) {
  TempDir dir;
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> u(0, 500);
  std::vector<Correspondence> ms;
  for (int i = 0; i < 1000; ++i) ms.push_back({{u(rng), u(rng)}, {u(rng), u(rng)}});
  ms.push_back({{1e-300, 0}, {499.99999999999994, 1.0 / 3.0}});
  const std::string path = dir.file("m.csv");
  writeMatches(path, ms);
  EXPECT_EQ(readMatches(path), ms);
  // An empty list is a header only, and reads back empty.
  writeMatches(dir.file("empty.csv"), {});
  EXPECT_TRUE(readMatches(dir.file("empty.csv")).empty());
}

TEST(MatchesFile, CommentsBlanksSeparatorsAndPixelCentres) {
  TempDir dir;
  const std::string path = dir.file("m.txt");
  writeBytes(path,
             "# from MASt3R\r\n\r\n  x0 y0\tx1 , y1\r\n"
             "10 20 30 40\r\n"
             "# a comment between data lines\n"
             "\n"
             "1.5e1,\t2.5 ,3.25,-4\n"
             "   5 6 7 8");  // no final newline
  const auto ms = readMatches(path);
  ASSERT_EQ(ms.size(), 3u);
  EXPECT_EQ(ms[0], (Correspondence{{10, 20}, {30, 40}}));
  EXPECT_EQ(ms[1], (Correspondence{{15, 2.5}, {3.25, -4}}));
  EXPECT_EQ(ms[2], (Correspondence{{5, 6}, {7, 8}}));
  // Integer pixel centres (OpenCV, numpy, MASt3R) move by +0.5.
  MatchesFileOptions o;
  o.pixel_center = 0;
  EXPECT_EQ(readMatches(path, o)[0], (Correspondence{{10.5, 20.5}, {30.5, 40.5}}));
}

TEST(MatchesFile, MalformedFilesNameFileAndLine) {
  TempDir dir;
  struct Case {
    std::string text, field;
  };
  const std::vector<Case> cases = {
      {"", "header"},
      {"# only comments\n\n", "header"},
      {"1,2,3,4\n", "line 1"},                           // no header
      {"x0,y0,x1\n1,2,3\n", "line 1"},                   // wrong header
      {"# c\nx0,y0,x1,y1\n1,2,3,4\n1,2,3\n", "line 4"},  // three fields
      {"x0,y0,x1,y1\n1,2,3,4,5\n", "line 2"},            // five fields
      {"x0,y0,x1,y1\n1,,3,4\n", "line 2"},               // empty field
      {"x0,y0,x1,y1\n1,2,3,4,\n", "line 2"},             // trailing comma
      {"x0,y0,x1,y1\n1,2,abc,4\n", "line 2"},            // not a number
      {"x0,y0,x1,y1\n1,2,3px,4\n", "line 2"},            // trailing junk
      {"x0,y0,x1,y1\n1,2,nan,4\n", "line 2"},            // not finite
      {"x0,y0,x1,y1\n1,2,inf,4\n", "line 2"},
      {"x0,y0,x1,y1\n1,2,1e999,4\n", "line 2"},  // overflows
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const std::string path = dir.file("bad" + std::to_string(i) + ".csv");
    writeBytes(path, cases[i].text);
    EXPECT_TRUE(throwsInputError([&] { readMatches(path); }, path, cases[i].field))
        << "case " << i << ": " << cases[i].text;
  }
  EXPECT_TRUE(throwsInputError([&] { readMatches(dir.file("missing.csv")); }, dir.file("missing.csv"), "file"));
}

TEST(Subsample, DenseInputGivesTheStrideGrid) {
  const int W = 23, H = 17, stride = 5;
  std::vector<Correspondence> dense;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) dense.push_back({{x + 0.5, y + 0.5}, {x + 1.0, y + 2.0}});
  const auto sub = subsampleByStride(dense, stride, W, H);
  std::vector<Correspondence> expected;
  for (int y = 0; y < H; y += stride)
    for (int x = 0; x < W; x += stride) expected.push_back({{x + 0.5, y + 0.5}, {x + 1.0, y + 2.0}});
  EXPECT_EQ(sub, expected);
  // Idempotent: thinning a thinned set changes nothing.
  EXPECT_EQ(subsampleByStride(sub, stride, W, H), sub);
  // Stride 1 keeps every pixel.
  EXPECT_EQ(subsampleByStride(dense, 1, W, H).size(), dense.size());
}

TEST(Subsample, SparseInputKeepsTheMatchNearestEachAnchorAndDropsOutsiders) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Correspondence> ms = {
      {{3.9, 3.9}, {0, 0}},  // cell (0,0), far from its anchor (0.5, 0.5)
      {{1.0, 0.7}, {1, 1}},  // cell (0,0), nearer: wins
      {{7.0, 1.0}, {2, 2}},  // cell (1,0), alone
      {{1.0, 0.7}, {3, 3}},  // the same x0 as the winner: the earlier one stays
      {{-0.1, 2}, {4, 4}},   // outside
      {{10.0, 2}, {5, 5}},   // x == width: outside
      {{nan, 2}, {6, 6}},    // not finite
  };
  const auto sub = subsampleByStride(ms, 5, 10, 10);
  ASSERT_EQ(sub.size(), 2u);
  EXPECT_EQ(sub[0], ms[1]);
  EXPECT_EQ(sub[1], ms[2]);
  EXPECT_TRUE(throwsInputError([&] { subsampleByStride(ms, 0, 10, 10); }, "lifting options", "stride"));
}
