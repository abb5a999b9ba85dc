// The ablation's tables, from the finished jobs' typed reports.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <tuple>

#include "nbv/eval/ablation.h"
#include "nbv/eval/paired_stats.h"

namespace saresgs {

std::string Table::markdown() const {
  std::ostringstream s;
  s << "### " << title << "\n\n|";
  for (const auto& h : header) s << " " << h << " |";
  s << "\n|";
  for (std::size_t i = 0; i < header.size(); ++i) s << (i == 0 ? "---|" : "---:|");
  s << "\n";
  for (const auto& r : rows) {
    s << "|";
    for (const auto& c : r) s << " " << c << " |";
    s << "\n";
  }
  return s.str();
}

std::string Table::csv() const {
  auto cell = [](const std::string& c) {
    // "24.59 ± 0.31" becomes two CSV fields; quotes where a comma would split a field.
    const std::string pm = " \u00b1 ";
    if (auto p = c.find(pm); p != std::string::npos) return c.substr(0, p) + "," + c.substr(p + pm.size());
    if (c.find(',') != std::string::npos) return "\"" + c + "\"";
    return c;
  };
  auto head = [&](const std::string& h, std::size_t col) {
    for (const auto& r : rows)
      if (col < r.size() && r[col].find(" \u00b1 ") != std::string::npos) return h + "_mean," + h + "_std";
    return h;
  };
  std::ostringstream s;
  for (std::size_t i = 0; i < header.size(); ++i) s << (i ? "," : "") << head(header[i], i);
  s << "\n";
  for (const auto& r : rows) {
    for (std::size_t i = 0; i < r.size(); ++i) s << (i ? "," : "") << cell(r[i]);
    s << "\n";
  }
  return s.str();
}

namespace {

std::string fmt(double v, int digits) {
  if (!std::isfinite(v)) return "n/a";
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", digits, v);
  return b;
}

std::string pm(const std::vector<double>& v, int digits) {
  if (v.empty()) return "n/a";
  const auto [m, s] = meanStd(v);
  return fmt(m, digits) + " \u00b1 " + fmt(s, digits);
}

bool isActive(const JobResult& r) { return r.job.kind == AblationJob::Kind::kActive; }

bool listed(const std::vector<std::string>& list, const std::string& name) {
  return list.empty() || std::find(list.begin(), list.end(), name) != list.end();
}

struct Key {
  std::string scene, method, variant;
  auto operator<=>(const Key&) const = default;
};

// The active runs grouped by (scene, method, variant), in job order within a group.
std::map<Key, std::vector<const RunReport*>> runsByKey(const std::vector<JobResult>& results) {
  std::map<Key, std::vector<const RunReport*>> by;
  for (const JobResult& r : results)
    if (isActive(r)) by[{r.job.scene, r.job.method, r.job.variant}].push_back(&r.run);
  return by;
}

// A metric over a group's runs, non-finite and missing values left out.
template <class Get>
std::vector<double> metric(const std::map<Key, std::vector<const RunReport*>>& by, const Key& k, Get&& get) {
  std::vector<double> v;
  if (auto it = by.find(k); it != by.end())
    for (const RunReport* r : it->second)
      if (const std::optional<double> x = get(*r); x && std::isfinite(*x)) v.push_back(*x);
  return v;
}

std::optional<double> psnrOf(const RunReport& r) { return r.psnr; }
std::optional<double> ssimOf(const RunReport& r) { return r.ssim; }
std::optional<double> auseOf(const RunReport& r) { return r.ause; }
std::optional<double> finalPsnrOf(const RunReport& r) {
  return r.final_fit ? std::optional<double>(r.final_fit->psnr) : std::nullopt;
}
std::optional<double> finalSsimOf(const RunReport& r) {
  return r.final_fit ? std::optional<double>(r.final_fit->ssim) : std::nullopt;
}
std::optional<double> plainRefitPsnrOf(const RunReport& r) {
  return r.final_fit_views ? std::optional<double>(r.final_fit_views->psnr) : std::nullopt;
}

// Config order for rows: scenes, methods, variants as listed.
template <class F>
void forEachCombo(const AblationGrid& g, F&& f) {
  for (const auto& sc : g.scenes)
    for (const auto& m : g.methods)
      for (const auto& v : g.variants) {
        if (!variantApplies(v, m)) continue;
        f(sc.name, m, v.name);
      }
}

}  // namespace

Table resultsTable(const AblationGrid& g, const std::vector<JobResult>& results) {
  const auto by = runsByKey(results);
  Table t{"results",
          "PSNR, SSIM and AUSE on the test views (mean \u00b1 std over seeds): the model of the loop (the paper's "
          "protocol); the final fit, a fresh model trained on exactly the chosen views with the method's own training "
          "(residual supervision for resgs and sa-resgs: selection judged apart from the schedule); and the plain "
          "refit, plain 3DGS on the same views (selection judged apart from the training too; the final fit itself "
          "for the methods that train plainly)",
          {"scene", "method", "seeds", "PSNR", "SSIM", "AUSE", "final-fit PSNR", "final-fit SSIM", "plain-refit PSNR"},
          {}};
  forEachCombo(g, [&](const std::string& s, const std::string& m, const std::string& v) {
    const Key k{s, m, v};
    const auto p = metric(by, k, psnrOf);
    if (p.empty()) return;
    t.rows.push_back({s, runLabel(m, v), std::to_string(p.size()), pm(p, 2), pm(metric(by, k, ssimOf), 4),
                      pm(metric(by, k, auseOf), 4), pm(metric(by, k, finalPsnrOf), 2),
                      pm(metric(by, k, finalSsimOf), 4), pm(metric(by, k, plainRefitPsnrOf), 2)});
  });
  return t;
}

// One PSNR column per scene plus the mean over scenes (per seed, then mean +- std over
// seeds), and the mean SSIM.
Table namedTable(const AblationGrid& g, const AblationTableSpec& spec, const std::vector<JobResult>& results) {
  const auto by = runsByKey(results);
  Table t{spec.name, spec.title, {"method"}, {}};
  for (const auto& sc : g.scenes) t.header.push_back(sc.name + " PSNR");
  t.header.push_back("mean PSNR");
  t.header.push_back("mean SSIM");
  for (const auto& m : g.methods) {
    if (!listed(spec.methods, m)) continue;
    for (const auto& v : g.variants) {
      if (!variantApplies(v, m) || !listed(spec.variants, v.name)) continue;
      std::vector<std::string> row{runLabel(m, v.name)};
      bool any = false;
      for (const auto& sc : g.scenes) {
        const auto p = metric(by, {sc.name, m, v.name}, psnrOf);
        any = any || !p.empty();
        row.push_back(pm(p, 2));
      }
      if (!any) continue;
      // Scene-averaged values per seed, over seeds that have every scene.
      std::vector<double> mp, ms;
      for (std::uint64_t seed : g.seeds) {
        double sp = 0, ss = 0;
        int n = 0;
        for (const JobResult& r : results)
          if (isActive(r) && r.job.method == m && r.job.variant == v.name && r.job.seed == seed) {
            sp += r.run.psnr;
            ss += r.run.ssim;
            ++n;
          }
        if (n == static_cast<int>(g.scenes.size())) {
          mp.push_back(sp / n);
          ms.push_back(ss / n);
        }
      }
      row.push_back(pm(mp, 2));
      row.push_back(pm(ms, 4));
      t.rows.push_back(row);
    }
  }
  return t;
}

// PSNR on the progress test views after training with k views (before selecting k+1);
// no rows when no run has steps.
Table psnrVsViewsTable(const AblationGrid& g, const std::vector<JobResult>& results) {
  Table t{"psnr_vs_views",
          "PSNR on the progress test views against the number of training views (mean over seeds; the "
          "progress views are 3 of the test views, so these are noisier than the final table)",
          {"scene", "method"},
          {}};
  int max_views = 0;
  for (const JobResult& r : results)
    if (isActive(r))
      for (const StepReport& s : r.run.steps) max_views = std::max(max_views, s.views_before);
  if (max_views == 0) return t;
  int min_views = max_views;
  for (const JobResult& r : results)
    if (isActive(r))
      for (const StepReport& s : r.run.steps) min_views = std::min(min_views, s.views_before);
  for (int k = min_views; k <= max_views; ++k) t.header.push_back(std::to_string(k));
  const auto by = runsByKey(results);
  forEachCombo(g, [&](const std::string& s, const std::string& m, const std::string& v) {
    auto it = by.find({s, m, v});
    if (it == by.end()) return;
    std::vector<std::string> row{s, runLabel(m, v)};
    for (int k = min_views; k <= max_views; ++k) {
      std::vector<double> p;
      for (const RunReport* r : it->second)
        for (const StepReport& st : r->steps)
          if (st.views_before == k) p.push_back(st.progress_psnr);
      row.push_back(p.empty() ? "" : fmt(meanStd(p).first, 2));
    }
    t.rows.push_back(row);
  });
  return t;
}

// Final-fit PSNR per test view: where in a scene a method's views fall short. Columns are
// the test views in split order (every method of a scene shares them; names are in each
// run's results.json). A view's cell is the mean over the seeds whose final fit has it.
Table finalFitPerViewTable(const AblationGrid& g, const std::vector<JobResult>& results) {
  Table t{"final_fit_per_view",
          "Final-fit PSNR per test view (mean over seeds; columns: the scene's test views in split order)",
          {"scene", "method", "n"},
          {}};
  std::size_t max_views = 0;
  for (const JobResult& r : results)
    if (isActive(r) && r.run.final_fit) max_views = std::max(max_views, r.run.final_fit->views.size());
  if (max_views == 0) return t;
  for (std::size_t k = 0; k < max_views; ++k) t.header.push_back(std::to_string(k));
  const auto by = runsByKey(results);
  forEachCombo(g, [&](const std::string& s, const std::string& m, const std::string& v) {
    auto it = by.find({s, m, v});
    if (it == by.end()) return;
    std::vector<std::vector<double>> per_view(max_views);
    int n = 0;
    for (const RunReport* r : it->second) {
      if (!r->final_fit) continue;
      ++n;
      for (std::size_t k = 0; k < r->final_fit->views.size(); ++k) per_view[k].push_back(r->final_fit->views[k].psnr);
    }
    if (n == 0) return;
    std::vector<std::string> row{s, runLabel(m, v), std::to_string(n)};
    for (const auto& p : per_view) row.push_back(p.empty() ? "" : fmt(meanStd(p).first, 2));
    t.rows.push_back(row);
  });
  return t;
}

// Time breakdown per method over all scenes and seeds (seconds per run unless named).
Table timeTable(const AblationGrid& g, const std::vector<JobResult>& results) {
  Table t{"time",
          "Time per run (mean over scenes and seeds, seconds): selection stages, training per iteration, end to "
          "end; coverage = the hybrid's visible-surface sets and counts; exhaustive Fisher = Fisher over all "
          "candidates timed in the same run",
          {"method", "runs", "lifting", "triangulation", "prefilter", "Fisher", "coverage", "selection",
           "exhaustive Fisher", "selection saved", "train ms/it", "end to end"},
          {}};
  for (const auto& m : g.methods)
    for (const auto& v : g.variants) {
      if (!variantApplies(v, m)) continue;
      std::vector<double> li, tr, pf, fi, cv, sel, ex, saved, it_ms, e2e;
      for (const JobResult& r : results) {
        if (!isActive(r) || r.job.method != m || r.job.variant != v.name) continue;
        const SelectionSeconds& st = r.run.seconds;
        li.push_back(st.lifting);
        tr.push_back(st.triangulation);
        pf.push_back(st.prefilter);
        fi.push_back(st.fisher);
        cv.push_back(st.coverage);
        sel.push_back(st.selection());
        if (st.exhaustive_fisher > 0) {
          ex.push_back(st.exhaustive_fisher);
          saved.push_back(100.0 * (1.0 - sel.back() / ex.back()));
        }
        if (r.run.iterations > 0) it_ms.push_back(1000.0 * st.training / r.run.iterations);
        e2e.push_back(r.run.end_to_end_seconds);
      }
      if (li.empty()) continue;
      auto mean = [](const std::vector<double>& x, int d) {
        return x.empty() ? std::string("") : fmt(meanStd(x).first, d);
      };
      t.rows.push_back({runLabel(m, v.name), std::to_string(li.size()), mean(li, 2), mean(tr, 3), mean(pf, 3),
                        mean(fi, 1), mean(cv, 2), mean(sel, 1), mean(ex, 1), saved.empty() ? "" : mean(saved, 0) + " %",
                        mean(it_ms, 1), mean(e2e, 0)});
    }
  return t;
}

// Prefilter sweep: per (set, score, encoding), the mean over observed states.
Table sweepTable(const std::vector<JobResult>& results) {
  Table t{
      "prefilter_sweep",
      "Prefilter variants against the exact visible-set reference (same score): top-N % overlap and Kendall "
      "tau-b of the candidate ranking (mean over observed states), scoring time per selection (encode + "
      "compare all candidates, median of repeats) and the time to build every candidate's voxel set once; "
      "grid: the scene type's occupancy grid (resolution, SfM points per voxel, scene-occupied voxels); load: "
      "scene voxels / hash table size",
      {"scene", "grid", "set", "score", "encoding", "load", "top-N overlap", "Kendall tau", "scoring ms", "sets ms"},
      {}};
  for (const JobResult& r : results) {
    if (r.job.kind != AblationJob::Kind::kSweep) continue;
    using RowKey = std::tuple<std::string, std::string, std::string>;
    std::map<RowKey, std::vector<const SweepRow*>> rows;
    std::vector<RowKey> order;
    for (const SweepRow& row : r.sweep.rows) {
      const RowKey k{row.set, row.score, row.encoding};
      if (!rows.count(k)) order.push_back(k);
      rows[k].push_back(&row);
    }
    const std::string grid = r.sweep.resolution > 0 ? r.sweep.scene_type + " r" + std::to_string(r.sweep.resolution) +
                                                          " m" + std::to_string(r.sweep.min_points) + ", " +
                                                          std::to_string(r.sweep.scene_voxels) + " voxels"
                                                    : "-";
    for (const auto& k : order) {
      std::vector<double> ov, tau, sc, st;
      double load = 0;
      for (const SweepRow* row : rows[k]) {
        ov.push_back(row->overlap);
        tau.push_back(row->kendall_tau);
        sc.push_back(1000 * row->seconds_scoring);
        st.push_back(1000 * row->seconds_sets);
        load = row->load;  // the same in every observed state
      }
      t.rows.push_back({r.job.scene, grid, std::get<0>(k), std::get<1>(k), std::get<2>(k),
                        load > 0 ? fmt(load, 3) : "-", fmt(meanStd(ov).first, 3), fmt(meanStd(tau).first, 3),
                        fmt(meanStd(sc).first, 2), fmt(meanStd(st).first, 1)});
    }
  }
  return t;
}

Table pairedTable(const AblationGrid& g, const std::vector<JobResult>& results) {
  Table t{"paired",
          "Paired differences against a baseline (method minus baseline; same initial model, trainer seed and test "
          "views per seed): mean over seeds, 95 % Student-t interval over seeds (undefined for one seed), seeds, and "
          "the share of (seed, test view) pairs the method wins (ties count half). final_fit_psnr: a fresh model "
          "trained on the chosen views with the method's own training (residual supervision for resgs and sa-resgs); "
          "plain_refit_psnr: plain 3DGS on the same views (selection alone); psnr: the loop's model (the paper's "
          "protocol); ause: the loop's model's AUSE of depth error against its uncertainty (lower is better, so a "
          "negative difference is the method's gain; no per-view win rate)",
          {"scene", "method", "baseline", "metric", "mean_diff", "ci_low", "ci_high", "n", "win_rate"},
          {}};
  // The run of (scene, method, variant, seed), if finished.
  auto find = [&](const std::string& scene, const std::string& m, const std::string& v,
                  std::uint64_t seed) -> const RunReport* {
    for (const JobResult& r : results)
      if (isActive(r) && r.job.scene == scene && r.job.method == m && r.job.variant == v && r.job.seed == seed)
        return &r.run;
    return nullptr;
  };
  enum class Model { kFinalFit, kPlainRefit, kLoop, kNone };  // kNone: no per-view figures
  struct Metric {
    const char* name;
    std::optional<double> (*value)(const RunReport&);
    Model model;
  };
  const Metric metrics[] = {{"final_fit_psnr", finalPsnrOf, Model::kFinalFit},
                            {"plain_refit_psnr", plainRefitPsnrOf, Model::kPlainRefit},
                            {"psnr", psnrOf, Model::kLoop},
                            {"ause", auseOf, Model::kNone}};
  auto viewPsnrs = [](const RunReport& r, Model m) {
    std::vector<double> v;
    const std::vector<ViewReport>& views = m == Model::kFinalFit     ? r.final_fit->views
                                           : m == Model::kPlainRefit ? r.final_fit_views->views
                                                                     : r.views;
    for (const ViewReport& x : views) v.push_back(x.psnr);
    return v;
  };
  for (const std::string baseline : {"random", "fisher", "fvs"}) {
    if (std::find(g.methods.begin(), g.methods.end(), baseline) == g.methods.end()) continue;
    forEachCombo(g, [&](const std::string& scene, const std::string& m, const std::string& v) {
      if (m == baseline && v == "default") return;
      for (const Metric& metric : metrics) {
        std::vector<double> a, b;
        std::vector<std::vector<double>> va, vb;
        for (std::uint64_t seed : g.seeds) {
          const RunReport* x = find(scene, m, v, seed);
          const RunReport* y = find(scene, baseline, "default", seed);
          if (!x || !y || !metric.value(*x) || !metric.value(*y)) continue;
          a.push_back(*metric.value(*x));
          b.push_back(*metric.value(*y));
          if (metric.model == Model::kNone) continue;
          va.push_back(viewPsnrs(*x, metric.model));
          vb.push_back(viewPsnrs(*y, metric.model));
        }
        if (a.empty()) continue;
        const PairedDifference d = pairedDifference(a, b, va, vb);
        auto opt = [](const std::optional<double>& x, int digits) {
          return x ? fmt(*x, digits) : std::string("undefined");
        };
        t.rows.push_back({scene, runLabel(m, v), baseline, metric.name, fmt(d.mean, 3), opt(d.ci_low, 3),
                          opt(d.ci_high, 3), std::to_string(d.n),
                          d.win_rate ? fmt(*d.win_rate, 3) : std::string("n/a")});
      }
    });
  }
  return t;
}

std::vector<BetterBaselineDifference> againstBetterBaseline(const AblationGrid& g,
                                                            const std::vector<JobResult>& results) {
  std::vector<BetterBaselineDifference> out;
  auto has = [&](const char* m) { return std::find(g.methods.begin(), g.methods.end(), m) != g.methods.end(); };
  if (!has("fisher") || !has("fvs")) return out;
  // Final-fit PSNR of (scene, method label) per seed.
  std::map<std::pair<std::string, std::string>, std::map<std::uint64_t, double>> fit;
  for (const JobResult& r : results)
    if (isActive(r))
      if (const auto p = finalPsnrOf(r.run)) fit[{r.job.scene, runLabel(r.job.method, r.job.variant)}][r.job.seed] = *p;
  auto paired = [&](const std::string& scene, const std::string& a, const std::string& b) {
    std::vector<double> x, y;
    const auto& fa = fit[{scene, a}];
    const auto& fb = fit[{scene, b}];
    for (const auto& [seed, v] : fa)
      if (const auto it = fb.find(seed); it != fb.end()) {
        x.push_back(v);
        y.push_back(it->second);
      }
    return x.empty() ? std::optional<PairedDifference>() : std::optional<PairedDifference>(pairedDifference(x, y));
  };
  for (const AblationScene& sc : g.scenes) {
    const auto baselines = paired(sc.name, "fisher", "fvs");
    if (!baselines) continue;
    const std::string better = baselines->mean >= 0 ? "fisher" : "fvs";
    forEachCombo(g, [&](const std::string& scene, const std::string& m, const std::string& v) {
      const std::string label = runLabel(m, v);
      if (scene != sc.name || label == better) return;
      if (const auto d = paired(scene, label, better)) out.push_back({scene, better, label, *d});
    });
  }
  return out;
}

Table betterBaselineTable(const AblationGrid& g, const std::vector<JobResult>& results) {
  Table t{"vs_better_baseline",
          "Final-fit PSNR against the better of fisher and fvs on each scene (the one ahead when the two are paired "
          "over their common seeds), paired by seed: mean difference, 95 % Student-t interval (undefined for one "
          "seed), seeds. A selector that beats both simple ones is above on every scene",
          {"scene", "baseline", "method", "mean_diff", "ci_low", "ci_high", "n", "verdict"},
          {}};
  for (const BetterBaselineDifference& r : againstBetterBaseline(g, results)) {
    auto opt = [](const std::optional<double>& x) { return x ? fmt(*x, 3) : std::string("undefined"); };
    const bool clear = r.d.ci_low && (*r.d.ci_low > 0 || *r.d.ci_high < 0);
    const std::string verdict =
        std::string(r.d.mean >= 0 ? "at or above" : "below") + (clear ? ", interval clear of 0" : "");
    t.rows.push_back({r.scene, r.baseline, r.method, fmt(r.d.mean, 3), opt(r.d.ci_low), opt(r.d.ci_high),
                      std::to_string(r.d.n), verdict});
  }
  return t;
}

std::vector<Table> ablationTables(const AblationGrid& g, const std::vector<JobResult>& results) {
  std::vector<Table> tables{resultsTable(g, results)};
  for (const AblationTableSpec& spec : g.tables) tables.push_back(namedTable(g, spec, results));
  // The remaining tables are left out when there is nothing to put in them.
  if (Table t = psnrVsViewsTable(g, results); t.header.size() > 2) tables.push_back(std::move(t));
  if (Table t = timeTable(g, results); !t.rows.empty()) tables.push_back(std::move(t));
  if (Table t = sweepTable(results); !t.rows.empty()) tables.push_back(std::move(t));
  if (Table t = pairedTable(g, results); !t.rows.empty()) tables.push_back(std::move(t));
  if (Table t = betterBaselineTable(g, results); !t.rows.empty()) tables.push_back(std::move(t));
  if (Table t = finalFitPerViewTable(g, results); !t.rows.empty()) tables.push_back(std::move(t));
  return tables;
}

}  // namespace saresgs
