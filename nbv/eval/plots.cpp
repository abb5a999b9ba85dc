#include "nbv/eval/plots.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace saresgs {

namespace {

const cv::Scalar kPalette[] = {{180, 119, 31},  {14, 127, 255}, {44, 160, 44},   {40, 39, 214},
                               {189, 103, 148}, {75, 86, 140},  {194, 119, 227}, {127, 127, 127},
                               {34, 189, 188},  {207, 190, 23}};  // BGR, the usual ten

std::string tick(double v) {
  char b[32];
  const double a = std::abs(v);
  if (a != 0 && (a < 1e-2 || a >= 1e5))
    std::snprintf(b, sizeof b, "%.0e", v);
  else if (a >= 100 || v == std::round(v))
    std::snprintf(b, sizeof b, "%.0f", v);
  else if (a >= 1)
    std::snprintf(b, sizeof b, "%.1f", v);
  else
    std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

// "Nice" linear ticks covering [lo, hi].
std::vector<double> linearTicks(double lo, double hi) {
  const double span = hi - lo;
  const double raw = span / 5;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * mag >= raw) {
      step = m * mag;
      break;
    }
  std::vector<double> t;
  for (double v = std::ceil(lo / step) * step; v <= hi + 1e-9 * span; v += step)
    t.push_back(std::abs(v) < 1e-12 * span ? 0 : v);
  return t;
}

void drawPanel(cv::Mat& img, const PlotPanel& p) {
  const int W = img.cols, H = img.rows;
  const int left = 62, right = 14, top = 30;
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  // The legend: entries left to right under the axis label, wrapped into as many rows as
  // the panel's width needs (the plot area gives up 16 px per extra row).
  std::vector<cv::Point> legend_at;
  {
    int x = left, row = 0;
    for (const PlotSeries& s : p.series) {
      const int w = 34 + cv::getTextSize(s.label, font, 0.4, 1, nullptr).width;
      if (x > left && x + w - 12 > W - right) {
        x = left;
        ++row;
      }
      legend_at.emplace_back(x, row);
      x += w;
    }
  }
  const int legend_rows = legend_at.empty() ? 1 : legend_at.back().y + 1;
  const int bottom = 78 + 16 * (legend_rows - 1);
  const cv::Scalar black(0, 0, 0), grey(225, 225, 225);
  auto fx = [&](double x) { return p.log_x ? std::log10(x) : x; };
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (const auto& s : p.series)
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i]) || (p.log_x && s.x[i] <= 0)) continue;
      const double e = i < s.err.size() && std::isfinite(s.err[i]) ? s.err[i] : 0;
      x0 = std::min(x0, fx(s.x[i]));
      x1 = std::max(x1, fx(s.x[i]));
      y0 = std::min(y0, s.y[i] - e);
      y1 = std::max(y1, s.y[i] + e);
    }
  cv::putText(img, p.title, cv::Point(left, 20), font, 0.5, black, 1, cv::LINE_AA);
  if (x0 > x1) {
    cv::putText(img, "no data", cv::Point(W / 2 - 30, H / 2), font, 0.5, black, 1, cv::LINE_AA);
    return;
  }
  if (!p.x_categories.empty()) {
    x0 = -0.5;
    x1 = static_cast<double>(p.x_categories.size()) - 0.5;
  }
  if (x1 - x0 < 1e-12) x0 -= 0.5, x1 += 0.5;
  if (y1 - y0 < 1e-12) y0 -= 0.5, y1 += 0.5;
  const double pad_x = p.x_categories.empty() ? 0.05 * (x1 - x0) : 0, pad_y = 0.08 * (y1 - y0);
  x0 -= pad_x, x1 += pad_x, y0 -= pad_y, y1 += pad_y;
  // A legend of very many rows squeezes the plot area, never below 40 px.
  const int pw = W - left - right, ph = std::max(40, H - top - bottom);
  auto P = [&](double x, double y) {
    return cv::Point(left + static_cast<int>(std::lround((fx(x) - x0) / (x1 - x0) * pw)),
                     top + ph - static_cast<int>(std::lround((y - y0) / (y1 - y0) * ph)));
  };
  auto Praw = [&](double fxv, double y) {  // x already in plot space
    return cv::Point(left + static_cast<int>(std::lround((fxv - x0) / (x1 - x0) * pw)),
                     top + ph - static_cast<int>(std::lround((y - y0) / (y1 - y0) * ph)));
  };
  // Grid and ticks.
  for (double y : linearTicks(y0, y1)) {
    const cv::Point a = Praw(x0, y), b = Praw(x1, y);
    cv::line(img, a, b, grey, 1);
    cv::putText(img, tick(y), cv::Point(4, a.y + 4), font, 0.38, black, 1, cv::LINE_AA);
  }
  // Category names wider than their slot alternate between two rows, so neighbours do
  // not overlap; the axis label then moves down a row.
  bool stagger = false;
  for (const std::string& name : p.x_categories) {
    int base = 0;
    stagger = stagger || cv::getTextSize(name, font, 0.38, 1, &base).width >
                             static_cast<double>(pw) / static_cast<double>(p.x_categories.size()) - 4;
  }
  if (!p.x_categories.empty()) {
    for (std::size_t i = 0; i < p.x_categories.size(); ++i) {
      const cv::Point a = Praw(static_cast<double>(i), y0);
      int base = 0;
      const cv::Size sz = cv::getTextSize(p.x_categories[i], font, 0.38, 1, &base);
      const int y = top + ph + 16 + (stagger && i % 2 ? 13 : 0);
      cv::putText(img, p.x_categories[i], cv::Point(a.x - sz.width / 2, y), font, 0.38, black, 1, cv::LINE_AA);
    }
  } else if (p.log_x) {
    // Decades, plus 2 and 5 within them when the axis spans less than two decades.
    const bool fine = x1 - x0 < 2;
    for (int e = static_cast<int>(std::floor(x0)); e <= static_cast<int>(std::ceil(x1)); ++e)
      for (double m : {1.0, 2.0, 5.0}) {
        if (m != 1.0 && !fine) continue;
        const double lx = e + std::log10(m);
        if (lx < x0 || lx > x1) continue;
        const cv::Point a = Praw(lx, y0), b = Praw(lx, y1);
        cv::line(img, a, b, grey, 1);
        cv::putText(img, tick(m * std::pow(10.0, e)), cv::Point(a.x - 12, top + ph + 16), font, 0.38, black, 1,
                    cv::LINE_AA);
      }
  } else {
    for (double x : linearTicks(x0, x1)) {
      const cv::Point a = Praw(x, y0), b = Praw(x, y1);
      cv::line(img, a, b, grey, 1);
      cv::putText(img, tick(x), cv::Point(a.x - 10, top + ph + 16), font, 0.38, black, 1, cv::LINE_AA);
    }
  }
  cv::rectangle(img, cv::Point(left, top), cv::Point(left + pw, top + ph), black, 1);
  cv::putText(img, p.xlabel,
              cv::Point(left + pw / 2 - 4 * static_cast<int>(p.xlabel.size()), top + ph + (stagger ? 46 : 36)), font,
              0.42, black, 1, cv::LINE_AA);
  cv::putText(img, p.ylabel, cv::Point(4, top - 8 + 0), font, 0.38, black, 1, cv::LINE_AA);

  for (std::size_t si = 0; si < p.series.size(); ++si) {
    const PlotSeries& s = p.series[si];
    const cv::Scalar c = kPalette[si % std::size(kPalette)];
    if (s.band) {
      // y - err along the series, then y + err back: one polygon, blended at 20 %.
      std::vector<cv::Point> lower, upper;
      for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
        if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i]) || (p.log_x && s.x[i] <= 0)) continue;
        const double e = i < s.err.size() && std::isfinite(s.err[i]) ? s.err[i] : 0.0;
        lower.push_back(P(s.x[i], s.y[i] - e));
        upper.push_back(P(s.x[i], s.y[i] + e));
      }
      if (lower.size() > 1) {
        std::vector<cv::Point> poly(lower.begin(), lower.end());
        poly.insert(poly.end(), upper.rbegin(), upper.rend());
        cv::Mat layer = img.clone();
        cv::fillPoly(layer, std::vector<std::vector<cv::Point>>{poly}, c, cv::LINE_AA);
        cv::addWeighted(layer, 0.2, img, 0.8, 0.0, img);
      }
    }
    std::vector<cv::Point> pts;
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i]) || (p.log_x && s.x[i] <= 0)) continue;
      const cv::Point q = P(s.x[i], s.y[i]);
      if (!s.band && i < s.err.size() && std::isfinite(s.err[i]) && s.err[i] > 0) {
        cv::line(img, P(s.x[i], s.y[i] - s.err[i]), P(s.x[i], s.y[i] + s.err[i]), c, 1, cv::LINE_AA);
        cv::line(img, P(s.x[i], s.y[i] - s.err[i]) + cv::Point(-4, 0), P(s.x[i], s.y[i] - s.err[i]) + cv::Point(4, 0),
                 c, 1);
        cv::line(img, P(s.x[i], s.y[i] + s.err[i]) + cv::Point(-4, 0), P(s.x[i], s.y[i] + s.err[i]) + cv::Point(4, 0),
                 c, 1);
      }
      cv::circle(img, q, 4, c, cv::FILLED, cv::LINE_AA);
      if (i < s.point_labels.size() && !s.point_labels[i].empty())
        cv::putText(img, s.point_labels[i], q + cv::Point(5, -5), font, 0.33, c, 1, cv::LINE_AA);
      pts.push_back(q);
    }
    if (s.lines && pts.size() > 1) cv::polylines(img, pts, false, c, 2, cv::LINE_AA);
    const int legend_x = legend_at[si].x, ly = H - 10 - 16 * (legend_rows - 1 - legend_at[si].y);
    cv::line(img, cv::Point(legend_x, ly - 4), cv::Point(legend_x + 18, ly - 4), c, 2, cv::LINE_AA);
    cv::putText(img, s.label, cv::Point(legend_x + 22, ly), font, 0.4, black, 1, cv::LINE_AA);
  }
}

}  // namespace

Image8 drawPlot(const std::vector<PlotPanel>& panels, int panel_w, int panel_h) {
  const int n = std::max<int>(1, static_cast<int>(panels.size()));
  cv::Mat img(panel_h, panel_w * n, CV_8UC3, cv::Scalar(255, 255, 255));
  for (int i = 0; i < static_cast<int>(panels.size()); ++i) {
    cv::Mat roi = img(cv::Rect(i * panel_w, 0, panel_w, panel_h));
    drawPanel(roi, panels[static_cast<std::size_t>(i)]);
  }
  cv::Mat rgb;
  cv::cvtColor(img, rgb, cv::COLOR_BGR2RGB);
  Image8 out(img.cols, img.rows, 3);
  std::memcpy(out.data.data(), rgb.data, out.data.size());
  return out;
}

}  // namespace saresgs
