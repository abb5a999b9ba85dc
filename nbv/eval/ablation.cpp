#include "nbv/eval/ablation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include "geometry/error.h"
#include "geometry/io/json_file.h"
#include "geometry/scene/manifest.h"
#include "nbv/prefilter_options.h"

namespace saresgs {

namespace fs = std::filesystem;

namespace {

// A method name from the config, checked against the one list of methods.
void checkMethod(const std::string& m, const std::string& file, const std::string& field) {
  try {
    (void)parseMethod(m);
  } catch (const std::invalid_argument& e) {
    throw InputError(file, field, e.what());
  }
}

// A sweep option parsed by the prefilter's parser, its message kept, the field named.
template <class F>
auto parsedAs(F&& parse, const std::string& file, const std::string& field) {
  try {
    return parse();
  } catch (const std::invalid_argument& e) {
    throw InputError(file, field, e.what());
  }
}

// The most threads a job may ask for (as `saresgs active --threads`).
constexpr long long kMaxThreads = 1024;

// A list whose items must differ (a repeat would run the same job twice).
template <class T>
void noRepeats(const std::vector<T>& items, const std::string& file, const std::string& field) {
  for (std::size_t i = 0; i < items.size(); ++i)
    for (std::size_t k = 0; k < i; ++k)
      if (items[i] == items[k]) {
        std::ostringstream s;
        s << items[i];
        throw InputError(file, jsonPath(field, i), s.str() + " appears twice");
      }
}

// Folder-safe: letters, digits, '.', '-', '_' only.
std::string safeName(const std::string& s, const std::string& file, const std::string& field) {
  if (s.empty()) throw InputError(file, field, "empty name");
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '_'))
      throw InputError(file, field, "'" + s + "': names may hold letters, digits, '.', '-' and '_' only");
  return s;
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

namespace {

// Calls read(item, "key[i]") for every item of the config's array `key`, each an object
// with a "name"; `expected` describes an item for the messages.
template <class F>
void forEachNamedObject(const nlohmann::json& j, const std::string& path, const std::string& key,
                        const std::string& expected, F&& read) {
  if (!j.is_array()) throw InputError(path, key, "expected an array of " + expected);
  for (std::size_t i = 0; i < j.size(); ++i) {
    const std::string f = key + "[" + std::to_string(i) + "]";
    if (!j[i].is_object() || !j[i].contains("name")) throw InputError(path, f, "expected " + expected);
    read(j[i], f);
  }
}

// The item's folder-safe name, which no earlier item of the same array had.
std::string uniqueName(const nlohmann::json& item, std::set<std::string>& seen, const std::string& path,
                       const std::string& f) {
  const std::string name = safeName(jsonString(item["name"], path, f + ".name"), path, f + ".name");
  if (!seen.insert(name).second) throw InputError(path, f + ".name", "'" + name + "' appears twice");
  return name;
}

std::vector<AblationScene> readScenes(const nlohmann::json& j, const std::string& path) {
  if (!j.contains("scenes") || j["scenes"].empty())
    throw InputError(path, "scenes", "expected a non-empty array of {name, dataset[, layout]}");
  std::vector<AblationScene> scenes;
  std::set<std::string> names;
  forEachNamedObject(
      j["scenes"], path, "scenes", "{name, dataset[, layout]}", [&](const nlohmann::json& s, const std::string& f) {
        if (!s.contains("dataset")) throw InputError(path, f, "expected {name, dataset[, layout]}");
        for (const auto& [key, value] : s.items())
          if (key != "name" && key != "dataset" && key != "layout" && key != "scene_seed")
            throw InputError(path, f + ".\"" + key + "\"",
                             "unknown field (expected name, dataset, layout, scene_seed)");
        AblationScene sc;
        sc.name = uniqueName(s, names, path, f);
        sc.dataset = jsonString(s["dataset"], path, f + ".dataset");
        if (s.contains("layout")) sc.layout = jsonString(s["layout"], path, f + ".layout");
        if (s.contains("scene_seed")) {
          if (!s["scene_seed"].is_number_unsigned())
            throw InputError(path, f + ".scene_seed", "expected a non-negative integer (saresgs scene --seed)");
          if (sc.layout.empty()) throw InputError(path, f + ".scene_seed", "given without a layout to generate");
          sc.scene_seed = s["scene_seed"].get<std::uint64_t>();
        }
        scenes.push_back(sc);
      });
  return scenes;
}

std::vector<AblationVariant> readVariants(const nlohmann::json& j, const std::string& path) {
  std::vector<AblationVariant> variants;
  std::set<std::string> names;
  forEachNamedObject(
      j, path, "variants", "{name, methods?, args?, replay?}", [&](const nlohmann::json& v, const std::string& f) {
        AblationVariant var;
        var.name = uniqueName(v, names, path, f);
        if (v.contains("methods")) var.methods = jsonStrings(v["methods"], path, f + ".methods");
        for (const auto& m : var.methods) checkMethod(m, path, f + ".methods");
        if (v.contains("args")) var.args = jsonStrings(v["args"], path, f + ".args");
        if (v.contains("replay")) {
          var.replay = jsonString(v["replay"], path, f + ".replay");
          checkMethod(var.replay, path, f + ".replay");
          if (var.name == "default")
            throw InputError(path, f + ".replay", "the default variant is what replays read: it cannot replay");
        }
        variants.push_back(var);
      });
  return variants;
}

std::vector<AblationTableSpec> readTables(const nlohmann::json& j, const std::string& path) {
  std::vector<AblationTableSpec> tables;
  std::set<std::string> names;
  forEachNamedObject(j, path, "tables", "{name, title, methods?, variants?}",
                     [&](const nlohmann::json& t, const std::string& f) {
                       AblationTableSpec spec;
                       spec.name = uniqueName(t, names, path, f);
                       spec.title = t.contains("title") ? jsonString(t["title"], path, f + ".title") : spec.name;
                       if (t.contains("methods")) spec.methods = jsonStrings(t["methods"], path, f + ".methods");
                       if (t.contains("variants")) spec.variants = jsonStrings(t["variants"], path, f + ".variants");
                       tables.push_back(spec);
                     });
  return tables;
}

SweepSpec readSweep(const nlohmann::json& s, const std::vector<AblationScene>& scenes, const std::string& path) {
  if (!s.is_object()) throw InputError(path, "sweep", "expected an object");
  SweepSpec sw;
  sw.scenes = s.contains("scenes") ? jsonStrings(s["scenes"], path, "sweep.scenes") : std::vector<std::string>{};
  if (sw.scenes.empty())
    for (const auto& sc : scenes) sw.scenes.push_back(sc.name);
  for (const auto& n : sw.scenes)
    if (std::none_of(scenes.begin(), scenes.end(), [&](const AblationScene& sc) { return sc.name == n; }))
      throw InputError(path, "sweep.scenes", "'" + n + "' is not one of the scenes");
  if (s.contains("views")) {
    sw.view_counts.clear();
    for (long long c : jsonIntegers(s["views"], path, "sweep.views", 1, kMaxSyntheticViews))
      sw.view_counts.push_back(static_cast<int>(c));
  }
  if (sw.view_counts.empty()) throw InputError(path, "sweep.views", "expected at least one view count");
  if (s.contains("encodings")) {
    sw.encodings.clear();
    for (const std::string& e : jsonStrings(s["encodings"], path, "sweep.encodings"))
      sw.encodings.push_back(parsedAs(
          [&] {
            CoverageScoring c;
            parseCoverageEncoding(e, c, kSweepMinHashBits, kSweepMaxHashBits);
            return c;
          },
          path, "sweep.encodings"));
  }
  if (s.contains("sets")) {
    sw.sets.clear();
    for (const std::string& k : jsonStrings(s["sets"], path, "sweep.sets"))
      sw.sets.push_back(parsedAs([&] { return parseCandidateSet(k); }, path, "sweep.sets"));
  }
  if (s.contains("scores")) {
    sw.scores.clear();
    for (const std::string& k : jsonStrings(s["scores"], path, "sweep.scores"))
      sw.scores.push_back(parsedAs([&] { return parseCoverageCriterion(k); }, path, "sweep.scores"));
  }
  if (s.contains("lifting")) {
    const std::string l = jsonString(s["lifting"], path, "sweep.lifting");
    sw.lifting = parsedAs([&] { return parseLiftingSource(l); }, path, "sweep.lifting");
  }
  if (s.contains("keep")) {
    sw.keep_fraction = jsonNumberIn(s["keep"], path, "sweep.keep", 0, 1);
    if (!(sw.keep_fraction > 0)) throw InputError(path, "sweep.keep", "expected a fraction in (0, 1]");
  }
  if (s.contains("timing_repeats"))
    sw.timing_repeats = static_cast<int>(jsonInteger(s["timing_repeats"], path, "sweep.timing_repeats", 1, 1000));
  return sw;
}

}  // namespace

AblationGrid readAblationGrid(const std::string& path) {
  const nlohmann::json j = readJsonFile(path);
  if (!j.is_object()) throw InputError(path, "json", "expected an object");
  AblationGrid g;
  g.source = path;
  for (const auto& [key, value] : j.items())
    if (!std::set<std::string>{"preset", "threads", "scenes", "methods", "seeds", "method_seeds", "method_args",
                               "variants", "tables", "sweep", "comment"}
             .count(key))
      // Quoted, so that an empty key (found by the ablation-config fuzz target) still names a field.
      throw InputError(path, "\"" + key + "\"", "unknown field");
  if (j.contains("preset")) g.preset = jsonString(j["preset"], path, "preset");
  if (g.preset != "quick" && g.preset != "paper") throw InputError(path, "preset", "expected quick or paper");
  if (j.contains("threads")) g.threads = static_cast<int>(jsonInteger(j["threads"], path, "threads", 0, kMaxThreads));
  g.scenes = readScenes(j, path);
  if (j.contains("methods")) g.methods = jsonStrings(j["methods"], path, "methods");
  for (const auto& m : g.methods) checkMethod(m, path, "methods");
  noRepeats(g.methods, path, "methods");
  if (j.contains("seeds"))
    for (long long s : jsonIntegers(j["seeds"], path, "seeds", 0, std::numeric_limits<long long>::max()))
      g.seeds.push_back(static_cast<std::uint64_t>(s));
  noRepeats(g.seeds, path, "seeds");
  if (g.seeds.empty()) g.seeds = {0};
  if (j.contains("method_seeds")) {
    if (!j["method_seeds"].is_object()) throw InputError(path, "method_seeds", "expected {method: [seeds]}");
    for (const auto& [m, a] : j["method_seeds"].items()) {
      const std::string f = "method_seeds." + m;
      checkMethod(m, path, "method_seeds");
      std::vector<std::uint64_t> seeds;
      for (long long s : jsonIntegers(a, path, f, 0, std::numeric_limits<long long>::max())) {
        if (std::find(g.seeds.begin(), g.seeds.end(), static_cast<std::uint64_t>(s)) == g.seeds.end())
          throw InputError(path, f,
                           "seed " + std::to_string(s) + " is not among \"seeds\" (the tables pair seeds from there)");
        seeds.push_back(static_cast<std::uint64_t>(s));
      }
      noRepeats(seeds, path, f);
      g.method_seeds[m] = seeds;
    }
  }
  if (j.contains("method_args")) {
    if (!j["method_args"].is_object()) throw InputError(path, "method_args", "expected {method: [args]}");
    for (const auto& [m, a] : j["method_args"].items()) {
      checkMethod(m, path, "method_args");
      g.method_args[m] = jsonStrings(a, path, "method_args." + m);
    }
  }
  if (j.contains("variants")) g.variants = readVariants(j["variants"], path);
  if (g.variants.empty()) g.variants.push_back({});
  if (j.contains("tables")) g.tables = readTables(j["tables"], path);
  if (j.contains("sweep")) g.sweep = readSweep(j["sweep"], g.scenes, path);
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
        const auto own = g.method_seeds.find(m);
        for (std::uint64_t seed : own != g.method_seeds.end() ? own->second : g.seeds) {
          AblationJob j;
          j.scene = sc.name;
          j.method = m;
          j.variant = v.name;
          j.seed = seed;
          j.id = sc.name + "__" + m + "__" + v.name + "__s" + std::to_string(seed);
          j.args = {"--dataset", sc.dataset, "--method", m, "--seed", std::to_string(seed), "--preset", g.preset};
          if (g.threads > 0) j.args.insert(j.args.end(), {"--threads", std::to_string(g.threads)});
          if (auto it = g.method_args.find(m); it != g.method_args.end())
            j.args.insert(j.args.end(), it->second.begin(), it->second.end());
          j.args.insert(j.args.end(), v.args.begin(), v.args.end());
          if (!v.replay.empty()) j.replay_of = sc.name + "__" + v.replay + "__default__s" + std::to_string(seed);
          jobs.push_back(j);
        }
      }
  // A replay's source is a default-variant job of the same grid.
  for (const AblationJob& j : jobs)
    if (!j.replay_of.empty() &&
        std::none_of(jobs.begin(), jobs.end(), [&](const AblationJob& s) { return s.id == j.replay_of; }))
      throw InputError(g.source, "variants",
                       "job " + j.id + " replays " + j.replay_of +
                           ", which the grid does not run (the replayed method needs the default variant)");
  return jobs;
}

std::string replaySource(const std::string& out, const AblationJob& j) {
  return j.replay_of.empty() ? std::string() : out + "/runs/" + j.replay_of + "/results.json";
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
  for (std::size_t k = static_cast<std::size_t>(i); k < jobs.size(); k += static_cast<std::size_t>(n))
    out.push_back(jobs[k]);
  return out;
}

std::string jobFolder(const std::string& out, const AblationJob& j) { return out + "/runs/" + j.id; }
std::string jobResultFile(const std::string& out, const AblationJob& j) {
  return jobFolder(out, j) + (j.kind == AblationJob::Kind::kSweep ? "/sweep.json" : "/results.json");
}
bool jobFinished(const std::string& out, const AblationJob& j) { return fs::exists(jobResultFile(out, j)); }

std::vector<JobResult> loadFinishedJobs(const std::string& out, const std::vector<AblationJob>& jobs) {
  std::vector<JobResult> r;
  for (const AblationJob& j : jobs) {
    if (!jobFinished(out, j)) continue;
    const std::string file = jobResultFile(out, j);
    JobResult res{j, {}, {}};
    if (j.kind == AblationJob::Kind::kSweep)
      res.sweep = sweepReportFromJson(readJsonFile(file), file);
    else
      res.run = runReportFromJson(readJsonFile(file), file);
    r.push_back(std::move(res));
  }
  return r;
}

}  // namespace saresgs
