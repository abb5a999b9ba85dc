// The results plots: the legend wraps into rows under the axis label instead of running
// off the panel, and a legend of many rows still leaves a plot of the asked size.
#include <gtest/gtest.h>

#include <string>

#include "nbv/eval/plots.h"

using namespace saresgs;

namespace {

PlotPanel panelWith(int series) {
  PlotPanel p{"t", "x", "y", false, {}, {}};
  for (int i = 0; i < series; ++i)
    p.series.push_back({"method number " + std::to_string(i), {0, 1}, {1.0 * i, 2.0 * i}, {}, {}, true});
  return p;
}

// Non-white pixels in rows [y0, y1) of the image.
int inkInRows(const Image8& img, int y0, int y1) {
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < 3; ++c) n += img.data[(static_cast<std::size_t>(y) * img.width + x) * 3 + c] < 200;
  return n;
}

}  // namespace

TEST(Plots, TheLegendWrapsIntoRowsUnderTheAxisLabel) {
  const int w = 560, h = 420;
  // One entry: one legend row at the bottom (text between h - 19 and h - 10); the band of
  // a second row above it (baseline h - 26) is empty, the x label sitting higher.
  const Image8 one = drawPlot({panelWith(1)}, w, h);
  ASSERT_EQ(one.width, w);
  ASSERT_EQ(one.height, h);
  EXPECT_GT(inkInRows(one, h - 19, h - 9), 0);
  EXPECT_EQ(inkInRows(one, h - 34, h - 27), 0);
  // Eight long labels do not fit in 560 px on one row: a second row appears.
  const Image8 eight = drawPlot({panelWith(8)}, w, h);
  EXPECT_GT(inkInRows(eight, h - 34, h - 27), 0);
  // Many rows squeeze the plot area but still give an image of the asked size.
  const Image8 many = drawPlot({panelWith(200)}, w, h);
  EXPECT_EQ(many.width, w);
  EXPECT_EQ(many.height, h);
}
