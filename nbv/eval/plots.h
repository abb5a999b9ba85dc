#pragma once
// Small x-y plots for the results pages (OpenCV drawing, no plotting library): panels
// side by side, each with axes, ticks, a legend, optional log x, error bars and
// categorical x labels.
#include <string>
#include <vector>

#include "geometry/image/image.h"

namespace saresgs {

struct PlotSeries {
  std::string label;
  std::vector<double> x, y;
  std::vector<double> err;                // optional: +- error bars on y
  std::vector<std::string> point_labels;  // optional: text beside each point
  bool lines = true;                      // join the points
  bool band = false;                      // draw err as a shaded band instead of bars
};

struct PlotPanel {
  std::string title, xlabel, ylabel;
  bool log_x = false;
  std::vector<std::string> x_categories;  // non-empty: x = 0, 1, ... are these names
  std::vector<PlotSeries> series;
};

// Panels left to right, each panel_w x panel_h pixels; non-finite points are skipped.
Image8 drawPlot(const std::vector<PlotPanel>& panels, int panel_w = 560, int panel_h = 420);

}  // namespace saresgs
