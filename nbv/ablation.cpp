#include "nbv/ablation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>
#include <stdexcept>

#include "geometry/error.h"
#include "geometry/io/json_file.h"

namespace saresgs {

namespace fs = std::filesystem;

namespace {

const std::set<std::string> kMethods = {"random", "fvs", "fisher", "coverage", "sa-hash", "sa-resgs", "resgs"};

template <class T>
T fieldAs(const nlohmann::json& j, const std::string& file, const std::string& field) {
  try {
    return j.get<T>();
  } catch (const nlohmann::json::exception&) {
    throw InputError(file, field, "unexpected type " + std::string(j.type_name()));
  }
}

std::vector<std::string> stringList(const nlohmann::json& j, const std::string& file, const std::string& field) {
  if (!j.is_array()) throw InputError(file, field, "expected an array of strings");
  return fieldAs<std::vector<std::string>>(j, file, field);
}

// Folder-safe: letters, digits, '.', '-', '_' only.
std::string safeName(const std::string& s, const std::string& file, const std::string& field) {
  if (s.empty()) throw InputError(file, field, "empty name");
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '_'))
      throw InputError(file, field, "'" + s + "': names may hold letters, digits, '.', '-' and '_' only");
  return s;
}

std::string fmt(double v, int digits) {
  if (!std::isfinite(v)) return "n/a";
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", digits, v);
  return b;
}

}  // namespace

std::pair<double, double> meanStd(const std::vector<double>& v) {
  if (v.empty()) return {0.0, 0.0};
  double m = 0;
  for (double x : v) m += x;
  m /= static_cast<double>(v.size());
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return {m, v.size() > 1 ? std::sqrt(s / static_cast<double>(v.size() - 1)) : 0.0};
}

bool variantApplies(const AblationVariant& v, const std::string& method) {
  return v.methods.empty() || std::find(v.methods.begin(), v.methods.end(), method) != v.methods.end();
}

std::string runLabel(const std::string& method, const std::string& variant) {
  return variant == "default" ? method : method + " (" + variant + ")";
}

double resultNumber(const nlohmann::json& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : NAN;
}

SelectionSeconds resultSeconds(const nlohmann::json& seconds) {
  SelectionSeconds s;
  s.lifting = resultNumber(seconds, "lifting");
  s.triangulation = resultNumber(seconds, "triangulation");
  s.prefilter = resultNumber(seconds, "prefilter");
  s.fisher = resultNumber(seconds, "fisher");
  s.training = resultNumber(seconds, "training");
  s.exhaustive_fisher = resultNumber(seconds, "exhaustive_fisher");
  return s;
}

AblationGrid readAblationGrid(const std::string& path) {
  const nlohmann::json j = readJsonFile(path);
  if (!j.is_object()) throw InputError(path, "json", "expected an object");
  AblationGrid g;
  g.source = path;
  for (const auto& [key, value] : j.items())
    if (!std::set<std::string>{"preset", "threads", "scenes", "methods", "seeds", "method_args", "variants", "tables", "sweep", "comment"}
             .count(key))
      throw InputError(path, key, "unknown field");
  if (j.contains("preset")) g.preset = fieldAs<std::string>(j["preset"], path, "preset");
  if (g.preset != "quick" && g.preset != "paper") throw InputError(path, "preset", "expected quick or paper");
  if (j.contains("threads")) g.threads = fieldAs<int>(j["threads"], path, "threads");
  if (g.threads < 0) throw InputError(path, "threads", "expected >= 0");
  if (!j.contains("scenes") || !j["scenes"].is_array() || j["scenes"].empty())
    throw InputError(path, "scenes", "expected a non-empty array of {name, dataset[, layout]}");
  std::set<std::string> scene_names;
  for (std::size_t i = 0; i < j["scenes"].size(); ++i) {
    const auto& s = j["scenes"][i];
    const std::string f = "scenes[" + std::to_string(i) + "]";
    if (!s.is_object() || !s.contains("name") || !s.contains("dataset")) throw InputError(path, f, "expected {name, dataset[, layout]}");
    AblationScene sc;
    sc.name = safeName(fieldAs<std::string>(s["name"], path, f + ".name"), path, f + ".name");
    sc.dataset = fieldAs<std::string>(s["dataset"], path, f + ".dataset");
    if (s.contains("layout")) sc.layout = fieldAs<std::string>(s["layout"], path, f + ".layout");
    if (!scene_names.insert(sc.name).second) throw InputError(path, f + ".name", "'" + sc.name + "' appears twice");
    g.scenes.push_back(sc);
  }
  if (j.contains("methods")) g.methods = stringList(j["methods"], path, "methods");
  for (const auto& m : g.methods)
    if (!kMethods.count(m)) throw InputError(path, "methods", "unknown method '" + m + "'");
  if (j.contains("seeds")) {
    if (!j["seeds"].is_array()) throw InputError(path, "seeds", "expected an array of integers");
    g.seeds = fieldAs<std::vector<std::uint64_t>>(j["seeds"], path, "seeds");
  }
  if (g.seeds.empty()) g.seeds = {0};
  if (j.contains("method_args")) {
    if (!j["method_args"].is_object()) throw InputError(path, "method_args", "expected {method: [args]}");
    for (const auto& [m, a] : j["method_args"].items()) {
      if (!kMethods.count(m)) throw InputError(path, "method_args", "unknown method '" + m + "'");
      g.method_args[m] = stringList(a, path, "method_args." + m);
    }
  }
  if (j.contains("variants")) {
    if (!j["variants"].is_array()) throw InputError(path, "variants", "expected an array of {name, methods?, args}");
    std::set<std::string> names;
    for (std::size_t i = 0; i < j["variants"].size(); ++i) {
      const auto& v = j["variants"][i];
      const std::string f = "variants[" + std::to_string(i) + "]";
      if (!v.is_object() || !v.contains("name")) throw InputError(path, f, "expected {name, methods?, args?}");
      AblationVariant var;
      var.name = safeName(fieldAs<std::string>(v["name"], path, f + ".name"), path, f + ".name");
      if (v.contains("methods")) var.methods = stringList(v["methods"], path, f + ".methods");
      for (const auto& m : var.methods)
        if (!kMethods.count(m)) throw InputError(path, f + ".methods", "unknown method '" + m + "'");
      if (v.contains("args")) var.args = stringList(v["args"], path, f + ".args");
      if (!names.insert(var.name).second) throw InputError(path, f + ".name", "'" + var.name + "' appears twice");
      g.variants.push_back(var);
    }
  }
  if (g.variants.empty()) g.variants.push_back({});
  if (j.contains("tables")) {
    if (!j["tables"].is_array()) throw InputError(path, "tables", "expected an array of {name, title, methods?, variants?}");
    for (std::size_t i = 0; i < j["tables"].size(); ++i) {
      const auto& t = j["tables"][i];
      const std::string f = "tables[" + std::to_string(i) + "]";
      if (!t.is_object() || !t.contains("name")) throw InputError(path, f, "expected {name, title, methods?, variants?}");
      AblationTableSpec spec;
      spec.name = safeName(fieldAs<std::string>(t["name"], path, f + ".name"), path, f + ".name");
      spec.title = t.contains("title") ? fieldAs<std::string>(t["title"], path, f + ".title") : spec.name;
      if (t.contains("methods")) spec.methods = stringList(t["methods"], path, f + ".methods");
      if (t.contains("variants")) spec.variants = stringList(t["variants"], path, f + ".variants");
      g.tables.push_back(spec);
    }
  }
  if (j.contains("sweep")) {
    const auto& s = j["sweep"];
    if (!s.is_object()) throw InputError(path, "sweep", "expected an object");
    SweepSpec sw;
    sw.scenes = s.contains("scenes") ? stringList(s["scenes"], path, "sweep.scenes") : std::vector<std::string>{};
    if (sw.scenes.empty())
      for (const auto& sc : g.scenes) sw.scenes.push_back(sc.name);
    for (const auto& n : sw.scenes)
      if (!scene_names.count(n)) throw InputError(path, "sweep.scenes", "'" + n + "' is not one of the scenes");
    if (s.contains("views")) sw.view_counts = fieldAs<std::vector<int>>(s["views"], path, "sweep.views");
    for (int c : sw.view_counts)
      if (c < 1) throw InputError(path, "sweep.views", "view counts must be >= 1");
    if (sw.view_counts.empty()) throw InputError(path, "sweep.views", "expected at least one view count");
    if (s.contains("encodings")) sw.encodings = stringList(s["encodings"], path, "sweep.encodings");
    if (s.contains("sets")) sw.sets = stringList(s["sets"], path, "sweep.sets");
    if (s.contains("scores")) sw.scores = stringList(s["scores"], path, "sweep.scores");
    if (s.contains("lifting")) sw.lifting = fieldAs<std::string>(s["lifting"], path, "sweep.lifting");
    if (s.contains("keep")) sw.keep_fraction = fieldAs<double>(s["keep"], path, "sweep.keep");
    if (s.contains("timing_repeats")) sw.timing_repeats = fieldAs<int>(s["timing_repeats"], path, "sweep.timing_repeats");
    g.sweep = sw;
  }
  if (g.methods.empty() && !g.sweep) throw InputError(path, "methods", "no methods and no sweep: nothing to run");
  return g;
}

std::vector<AblationJob> expandGrid(const AblationGrid& g) {
  std::vector<AblationJob> jobs;
  if (g.sweep)
    for (const auto& s : g.sweep->scenes) {
      AblationJob j;
      j.kind = AblationJob::Kind::kSweep;
      j.scene = s;
      j.id = s + "__prefilter-sweep";
      jobs.push_back(j);
    }
  for (const AblationScene& sc : g.scenes)
    for (const std::string& m : g.methods)
      for (const AblationVariant& v : g.variants) {
        if (!variantApplies(v, m)) continue;
        for (std::uint64_t seed : g.seeds) {
          AblationJob j;
          j.scene = sc.name;
          j.method = m;
          j.variant = v.name;
          j.seed = seed;
          j.id = sc.name + "__" + m + "__" + v.name + "__s" + std::to_string(seed);
          j.args = {"--dataset", sc.dataset, "--method", m, "--seed", std::to_string(seed), "--preset", g.preset};
          if (g.threads > 0) j.args.insert(j.args.end(), {"--threads", std::to_string(g.threads)});
          if (auto it = g.method_args.find(m); it != g.method_args.end()) j.args.insert(j.args.end(), it->second.begin(), it->second.end());
          j.args.insert(j.args.end(), v.args.begin(), v.args.end());
          jobs.push_back(j);
        }
      }
  return jobs;
}

std::pair<int, int> parseShard(const std::string& text) {
  int i = -1, n = 0;
  char extra = 0;
  if (std::sscanf(text.c_str(), "%d/%d%c", &i, &n, &extra) != 2 || n < 1 || i < 0 || i >= n)
    throw std::invalid_argument("--shard '" + text + "': expected i/n with 0 <= i < n");
  return {i, n};
}

std::vector<AblationJob> shardJobs(const std::vector<AblationJob>& jobs, int i, int n) {
  if (n < 1 || i < 0 || i >= n) throw std::invalid_argument("shard " + std::to_string(i) + "/" + std::to_string(n));
  std::vector<AblationJob> out;
  for (std::size_t k = static_cast<std::size_t>(i); k < jobs.size(); k += static_cast<std::size_t>(n)) out.push_back(jobs[k]);
  return out;
}

std::string jobFolder(const std::string& out, const AblationJob& j) { return out + "/runs/" + j.id; }
std::string jobResultFile(const std::string& out, const AblationJob& j) {
  return jobFolder(out, j) + (j.kind == AblationJob::Kind::kSweep ? "/sweep.json" : "/results.json");
}
bool jobFinished(const std::string& out, const AblationJob& j) { return fs::exists(jobResultFile(out, j)); }

std::vector<JobResult> loadFinishedJobs(const std::string& out, const std::vector<AblationJob>& jobs) {
  std::vector<JobResult> r;
  for (const AblationJob& j : jobs)
    if (jobFinished(out, j)) r.push_back({j, readJsonFile(jobResultFile(out, j))});
  return r;
}

// ---- tables ------------------------------------------------------------------------

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

std::string pm(const std::vector<double>& v, int digits) {
  if (v.empty()) return "n/a";
  const auto [m, s] = meanStd(v);
  return fmt(m, digits) + " \u00b1 " + fmt(s, digits);
}

struct Key {
  std::string scene, method, variant;
  auto operator<=>(const Key&) const = default;
};

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

std::vector<Table> ablationTables(const AblationGrid& g, const std::vector<JobResult>& results) {
  std::map<Key, std::vector<const nlohmann::json*>> by;
  for (const JobResult& r : results)
    if (r.job.kind == AblationJob::Kind::kActive) by[{r.job.scene, r.job.method, r.job.variant}].push_back(&r.result);
  auto values = [&](const Key& k, const char* field) {
    std::vector<double> v;
    if (auto it = by.find(k); it != by.end())
      for (const auto* j : it->second)
        if (std::isfinite(resultNumber(*j, field))) v.push_back(resultNumber(*j, field));
    return v;
  };
  std::vector<Table> tables;

  // Per scene and method, mean +- std over seeds.
  Table main{"results", "PSNR, SSIM and AUSE on the test views (mean \u00b1 std over seeds)",
             {"scene", "method", "seeds", "PSNR", "SSIM", "AUSE"}, {}};
  forEachCombo(g, [&](const std::string& s, const std::string& m, const std::string& v) {
    const Key k{s, m, v};
    const auto p = values(k, "psnr");
    if (p.empty()) return;
    main.rows.push_back({s, runLabel(m, v), std::to_string(p.size()), pm(p, 2), pm(values(k, "ssim"), 4), pm(values(k, "ause"), 4)});
  });
  tables.push_back(main);

  // Named tables: one PSNR column per scene plus the mean over scenes (per seed, then
  // mean +- std over seeds), and the mean SSIM.
  for (const AblationTableSpec& spec : g.tables) {
    Table t{spec.name, spec.title, {"method"}, {}};
    for (const auto& sc : g.scenes) t.header.push_back(sc.name + " PSNR");
    t.header.push_back("mean PSNR");
    t.header.push_back("mean SSIM");
    for (const auto& m : g.methods) {
      if (!spec.methods.empty() && std::find(spec.methods.begin(), spec.methods.end(), m) == spec.methods.end()) continue;
      for (const auto& v : g.variants) {
        if (!variantApplies(v, m)) continue;
        if (!spec.variants.empty() && std::find(spec.variants.begin(), spec.variants.end(), v.name) == spec.variants.end()) continue;
        std::vector<std::string> row{runLabel(m, v.name)};
        bool any = false;
        for (const auto& sc : g.scenes) {
          const auto p = values({sc.name, m, v.name}, "psnr");
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
            if (r.job.kind == AblationJob::Kind::kActive && r.job.method == m && r.job.variant == v.name && r.job.seed == seed) {
              sp += resultNumber(r.result, "psnr");
              ss += resultNumber(r.result, "ssim");
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
    tables.push_back(t);
  }

  // PSNR on the progress test views after training with k views (before selecting k+1).
  int max_views = 0;
  for (const JobResult& r : results)
    if (r.job.kind == AblationJob::Kind::kActive && r.result.contains("steps"))
      for (const auto& s : r.result["steps"]) max_views = std::max(max_views, s.value("views_before", 0));
  if (max_views > 0) {
    int min_views = max_views;
    for (const JobResult& r : results)
      if (r.job.kind == AblationJob::Kind::kActive && r.result.contains("steps"))
        for (const auto& s : r.result["steps"]) min_views = std::min(min_views, s.value("views_before", max_views));
    Table t{"psnr_vs_views",
            "PSNR on the progress test views against the number of training views (mean over seeds; the "
            "progress views are 3 of the test views, so these are noisier than the final table)",
            {"scene", "method"}, {}};
    for (int k = min_views; k <= max_views; ++k) t.header.push_back(std::to_string(k));
    forEachCombo(g, [&](const std::string& s, const std::string& m, const std::string& v) {
      auto it = by.find({s, m, v});
      if (it == by.end()) return;
      std::vector<std::string> row{s, runLabel(m, v)};
      for (int k = min_views; k <= max_views; ++k) {
        std::vector<double> p;
        for (const auto* j : it->second)
          for (const auto& st : (*j)["steps"])
            if (st.value("views_before", -1) == k) p.push_back(st.value("progress_psnr", NAN));
        row.push_back(p.empty() ? "" : fmt(meanStd(p).first, 2));
      }
      t.rows.push_back(row);
    });
    tables.push_back(t);
  }

  // Time breakdown per method over all scenes and seeds (seconds per run unless named).
  Table time{"time",
             "Time per run (mean over scenes and seeds, seconds): selection stages, training per iteration, end to "
             "end; exhaustive Fisher = Fisher over all candidates timed in the same run",
             {"method", "runs", "lifting", "triangulation", "prefilter", "Fisher", "selection", "exhaustive Fisher",
              "selection saved", "train ms/it", "end to end"},
             {}};
  for (const auto& m : g.methods)
    for (const auto& v : g.variants) {
      if (!variantApplies(v, m)) continue;
      std::vector<double> li, tr, pf, fi, sel, ex, saved, it_ms, e2e;
      for (const JobResult& r : results) {
        if (r.job.kind != AblationJob::Kind::kActive || r.job.method != m || r.job.variant != v.name) continue;
        const auto& s = r.result["seconds"];
        const SelectionSeconds st = resultSeconds(s);
        li.push_back(st.lifting);
        tr.push_back(st.triangulation);
        pf.push_back(st.prefilter);
        fi.push_back(st.fisher);
        sel.push_back(st.selection());
        if (st.exhaustive_fisher > 0) {
          ex.push_back(st.exhaustive_fisher);
          saved.push_back(100.0 * (1.0 - sel.back() / ex.back()));
        }
        const double its = resultNumber(r.result, "iterations");
        if (its > 0) it_ms.push_back(1000.0 * st.training / its);
        e2e.push_back(resultNumber(s, "end_to_end_this_process"));
      }
      if (li.empty()) continue;
      auto mean = [](const std::vector<double>& x, int d) { return x.empty() ? std::string("") : fmt(meanStd(x).first, d); };
      time.rows.push_back({runLabel(m, v.name), std::to_string(li.size()), mean(li, 2), mean(tr, 3), mean(pf, 3), mean(fi, 1),
                           mean(sel, 1), mean(ex, 1), saved.empty() ? "" : mean(saved, 0) + " %", mean(it_ms, 1), mean(e2e, 0)});
    }
  if (!time.rows.empty()) tables.push_back(time);

  // Prefilter sweep: mean over observed states.
  Table sweep{"prefilter_sweep",
              "Prefilter variants against the exact visible-set reference (same score): top-N % overlap and Kendall "
              "tau-b of the candidate ranking (mean over observed states), scoring time per selection (encode + "
              "compare all candidates, median of repeats) and the time to build every candidate's voxel set once",
              {"scene", "set", "score", "encoding", "top-N overlap", "Kendall tau", "scoring ms", "sets ms"},
              {}};
  for (const JobResult& r : results) {
    if (r.job.kind != AblationJob::Kind::kSweep) continue;
    std::map<std::tuple<std::string, std::string, std::string>, std::vector<const nlohmann::json*>> rows;
    std::vector<std::tuple<std::string, std::string, std::string>> order;
    for (const auto& row : r.result["rows"]) {
      auto k = std::make_tuple(row["set"].get<std::string>(), row["score"].get<std::string>(), row["encoding"].get<std::string>());
      if (!rows.count(k)) order.push_back(k);
      rows[k].push_back(&row);
    }
    for (const auto& k : order) {
      std::vector<double> ov, tau, sc, st;
      for (const auto* row : rows[k]) {
        ov.push_back(resultNumber(*row, "overlap"));
        tau.push_back(resultNumber(*row, "kendall_tau"));
        sc.push_back(1000 * resultNumber(*row, "seconds_scoring"));
        st.push_back(1000 * resultNumber(*row, "seconds_sets"));
      }
      sweep.rows.push_back({r.job.scene, std::get<0>(k), std::get<1>(k), std::get<2>(k), fmt(meanStd(ov).first, 3),
                            fmt(meanStd(tau).first, 3), fmt(meanStd(sc).first, 2), fmt(meanStd(st).first, 1)});
    }
  }
  if (!sweep.rows.empty()) tables.push_back(sweep);
  return tables;
}

}  // namespace saresgs
