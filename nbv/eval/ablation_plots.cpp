// The ablation's pictures, drawn from the same finished-job results as its tables.
#include <algorithm>
#include <cmath>
#include <map>

#include "nbv/eval/ablation.h"
#include "nbv/eval/paired_stats.h"
#include "nbv/eval/plots.h"

namespace saresgs {

namespace {

std::string label(const AblationJob& j) { return runLabel(j.method, j.variant); }

// Method labels in config order that have results for `scene`.
std::vector<std::string> labelsFor(const std::vector<JobResult>& results, const std::string& scene) {
  std::vector<std::string> out;
  for (const JobResult& r : results)
    if (r.job.kind == AblationJob::Kind::kActive && r.job.scene == scene &&
        std::find(out.begin(), out.end(), label(r.job)) == out.end())
      out.push_back(label(r.job));
  return out;
}

// Half the width of the 95 % Student-t interval of a mean over runs; NaN (no bar) for
// fewer than two runs, where it is undefined.
double halfInterval95(const std::vector<double>& v) {
  if (v.size() < 2) return std::nan("");
  return studentT975(static_cast<int>(v.size()) - 1) * meanStd(v).second / std::sqrt(static_cast<double>(v.size()));
}

// Final-fit PSNR per test view (mean over seeds), one line per method: where in a scene
// a method's views fall short (a region none of them saw shows as a dip on its views).
void addPerViewPlot(const AblationGrid& g, const std::vector<JobResult>& results, std::vector<NamedPlot>& plots) {
  std::vector<PlotPanel> panels;
  for (const AblationScene& sc : g.scenes) {
    PlotPanel p{
        sc.name + ": final-fit PSNR per test view (mean, seeds)", "test view (split order)", "PSNR dB", false, {}, {}};
    for (const std::string& l : labelsFor(results, sc.name)) {
      std::vector<std::vector<double>> per_view;
      for (const JobResult& r : results) {
        if (r.job.kind != AblationJob::Kind::kActive || r.job.scene != sc.name || label(r.job) != l || !r.run.final_fit)
          continue;
        const auto& views = r.run.final_fit->views;
        if (per_view.size() < views.size()) per_view.resize(views.size());
        for (std::size_t k = 0; k < views.size(); ++k) per_view[k].push_back(views[k].psnr);
      }
      if (per_view.empty()) continue;
      PlotSeries s{l, {}, {}, {}, {}, true};
      for (std::size_t k = 0; k < per_view.size(); ++k) {
        s.x.push_back(static_cast<double>(k));
        s.y.push_back(meanStd(per_view[k]).first);
      }
      p.series.push_back(s);
    }
    if (!p.series.empty()) panels.push_back(p);
  }
  if (!panels.empty()) plots.push_back({"final_fit_per_view", drawPlot(panels, 720, 420)});
}

// againstBetterBaseline as a picture: per scene, each method's mean paired difference
// with its 95 % t interval (no bar for one seed; the seeds beside each point) and a line at
// zero. A method above the line with its bar clear of it beats both simple selectors there.
void addBetterBaselinePlot(const AblationGrid& g, const std::vector<JobResult>& results,
                           std::vector<NamedPlot>& plots) {
  const std::vector<BetterBaselineDifference> rows = againstBetterBaseline(g, results);
  std::vector<PlotPanel> panels;
  for (const AblationScene& sc : g.scenes) {
    std::vector<std::string> labels;
    std::string baseline;
    PlotSeries diff{"mean, 95% t interval; seeds beside", {}, {}, {}, {}, false};
    for (const BetterBaselineDifference& r : rows) {
      if (r.scene != sc.name) continue;
      baseline = r.baseline;
      diff.x.push_back(static_cast<double>(labels.size()));
      diff.y.push_back(r.d.mean);
      diff.err.push_back(r.d.ci_low ? 0.5 * (*r.d.ci_high - *r.d.ci_low) : std::nan(""));
      diff.point_labels.push_back(std::to_string(r.d.n));
      labels.push_back(r.method);
    }
    if (labels.empty()) continue;
    PlotPanel p{
        sc.name + ": final-fit PSNR minus " + baseline + "'s (the better baseline)", "method", "dB", false, labels, {}};
    // The zero line first, so that the points are drawn over it.
    p.series.push_back({"0", {0.0, static_cast<double>(labels.size() - 1)}, {0.0, 0.0}, {}, {}, true});
    p.series.push_back(diff);
    panels.push_back(p);
  }
  if (!panels.empty()) plots.push_back({"final_fit_vs_better_baseline", drawPlot(panels)});
}

// In-loop PSNR per method, final-fit PSNR per method, PSNR against views (bands over
// seeds) and PSNR against selection time: one panel per scene in each.
void addActivePlots(const AblationGrid& g, const std::vector<JobResult>& results, std::vector<NamedPlot>& plots) {
  std::vector<PlotPanel> psnr, final_fit, views, time;
  for (const AblationScene& sc : g.scenes) {
    const std::vector<std::string> labels = labelsFor(results, sc.name);
    if (labels.empty()) continue;
    PlotPanel p{sc.name + ": test PSNR (mean +- std over seeds)", "method", "PSNR dB", false, labels, {}};
    PlotSeries ps{"PSNR", {}, {}, {}, {}, false};
    PlotPanel f{sc.name + ": final-fit PSNR (95% t interval, seeds)", "method", "PSNR dB", false, labels, {}};
    PlotSeries fs{"final fit", {}, {}, {}, {}, false};
    PlotPanel v{sc.name + ": progress PSNR (band: +- std, seeds)", "training views", "PSNR dB", false, {}, {}};
    PlotPanel t{sc.name + ": PSNR against selection time", "selection seconds per run (log)", "PSNR dB", true, {}, {}};
    for (std::size_t li = 0; li < labels.size(); ++li) {
      std::vector<double> p_runs, sel_runs, f_runs;
      std::map<int, std::vector<double>> by_views;
      for (const JobResult& r : results) {
        if (r.job.kind != AblationJob::Kind::kActive || r.job.scene != sc.name || label(r.job) != labels[li]) continue;
        p_runs.push_back(r.run.psnr);
        if (r.run.final_fit) f_runs.push_back(r.run.final_fit->psnr);
        sel_runs.push_back(r.run.seconds.selection());
        for (const StepReport& st : r.run.steps) by_views[st.views_before].push_back(st.progress_psnr);
      }
      const auto [pm, pstd] = meanStd(p_runs);
      ps.x.push_back(static_cast<double>(li));
      ps.y.push_back(pm);
      ps.err.push_back(pstd);
      if (!f_runs.empty()) {
        fs.x.push_back(static_cast<double>(li));
        fs.y.push_back(meanStd(f_runs).first);
        fs.err.push_back(halfInterval95(f_runs));
      }
      PlotSeries vs{labels[li], {}, {}, {}, {}, true};
      vs.band = true;
      for (const auto& [k, vals] : by_views) {
        vs.x.push_back(k);
        vs.y.push_back(meanStd(vals).first);
        vs.err.push_back(meanStd(vals).second);
      }
      v.series.push_back(vs);
      // Methods without a selection cost (random) sit at 1 ms so that the log axis shows them.
      t.series.push_back({labels[li], {std::max(1e-3, meanStd(sel_runs).first)}, {pm}, {pstd}, {}, false});
    }
    p.series.push_back(ps);
    psnr.push_back(p);
    if (!fs.x.empty()) {
      f.series.push_back(fs);
      final_fit.push_back(f);
    }
    views.push_back(v);
    time.push_back(t);
  }
  plots.push_back({"psnr", drawPlot(psnr)});
  addPerViewPlot(g, results, plots);
  if (!final_fit.empty()) plots.push_back({"final_fit_psnr", drawPlot(final_fit)});
  addBetterBaselinePlot(g, results, plots);
  plots.push_back({"psnr_vs_views", drawPlot(views)});
  plots.push_back({"psnr_vs_selection_time", drawPlot(time)});
}

// The sweep of one scene: ranking error (tau, overlap) against scoring time. One series
// per (set, score); points are the encodings.
NamedPlot sweepPlot(const JobResult& r) {
  std::map<std::string, std::map<std::string, std::vector<const SweepRow*>>> groups;  // series -> encoding -> rows
  std::vector<std::string> series_order, enc_order;
  for (const SweepRow& row : r.sweep.rows) {
    const std::string s = row.set + " " + row.score;
    const std::string& e = row.encoding;
    if (!groups.count(s)) series_order.push_back(s);
    if (std::find(enc_order.begin(), enc_order.end(), e) == enc_order.end()) enc_order.push_back(e);
    groups[s][e].push_back(&row);
  }
  // x: the scoring cost, which the encoding sets; building the candidates' sets (the
  // same for every encoding of a set kind) is in the table's "sets ms".
  const char* xl = "scoring ms per selection (log; set building not included)";
  PlotPanel tau{r.job.scene + ": ranking vs exact visible (Kendall tau-b)", xl, "tau", true, {}, {}};
  PlotPanel ov{r.job.scene + ": top-20% overlap with exact visible", xl, "overlap", true, {}, {}};
  for (const std::string& s : series_order) {
    PlotSeries a{s, {}, {}, {}, {}, true}, b{s, {}, {}, {}, {}, true};
    for (const std::string& e : enc_order) {
      auto it = groups[s].find(e);
      if (it == groups[s].end()) continue;
      std::vector<double> t, k, o;
      for (const auto* row : it->second) {
        t.push_back(1000 * row->seconds_scoring);
        k.push_back(row->kendall_tau);
        o.push_back(row->overlap);
      }
      const std::string pl = e == "exact" ? "ex" : e.substr(e.find(':') + 1);
      a.x.push_back(meanStd(t).first);
      a.y.push_back(meanStd(k).first);
      a.point_labels.push_back(pl);
      b.x.push_back(meanStd(t).first);
      b.y.push_back(meanStd(o).first);
      b.point_labels.push_back(pl);
    }
    tau.series.push_back(a);
    ov.series.push_back(b);
  }
  return {"prefilter_sweep_" + r.job.scene, drawPlot({tau, ov})};
}

}  // namespace

std::vector<NamedPlot> ablationPlots(const AblationGrid& g, const std::vector<JobResult>& results) {
  std::vector<NamedPlot> plots;
  if (std::any_of(results.begin(), results.end(),
                  [](const JobResult& r) { return r.job.kind == AblationJob::Kind::kActive; }))
    addActivePlots(g, results, plots);
  for (const JobResult& r : results)
    if (r.job.kind == AblationJob::Kind::kSweep) plots.push_back(sweepPlot(r));
  return plots;
}

}  // namespace saresgs
