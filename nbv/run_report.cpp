#include "nbv/run_report.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <map>
#include <type_traits>

#include "geometry/error.h"
#include "geometry/io/json_file.h"
#include "geometry/scene/cameras_json.h"
#include "splat/train/residual.h"

namespace saresgs {

namespace {

using json = nlohmann::json;

// j[key] as T; InputError(source, path.key) when it is missing, of another type or, for
// counts, negative or fractional.
template <class T>
T field(const json& j, const char* key, const std::string& source, const std::string& path) {
  const std::string name = jsonPath(path, key);
  const json& v = jsonMember(j, key, source, path);
  if constexpr (std::is_same_v<T, std::string>) return jsonString(v, source, name);
  else if constexpr (std::is_same_v<T, bool>) return jsonBool(v, source, name);
  else if constexpr (std::is_same_v<T, double>) return jsonNumber(v, source, name);
  else if constexpr (std::is_integral_v<T>)
    return static_cast<T>(jsonInteger(v, source, name, 0, static_cast<long long>(std::min<std::uint64_t>(std::numeric_limits<T>::max(), std::numeric_limits<long long>::max()))));
  else if constexpr (std::is_same_v<T, std::vector<std::string>>) return jsonStrings(v, source, name);
  else if constexpr (std::is_same_v<T, std::vector<double>>) return jsonNumbers(v, source, name);
  else {
    static_assert(std::is_same_v<T, std::vector<int>>);
    std::vector<int> out;
    for (long long x : jsonIntegers(v, source, name, 0, std::numeric_limits<int>::max())) out.push_back(static_cast<int>(x));
    return out;
  }
}

// The optional per-view array `j["views"]` (named `path` in messages).
void readViews(const json& j, const std::string& src, const std::string& path, std::vector<ViewReport>& out) {
  if (!j.contains("views")) return;
  jsonArray(j["views"], src, path);
  for (std::size_t i = 0; i < j["views"].size(); ++i) {
    const std::string p = jsonPath(path, i);
    const json& v = j["views"][i];
    out.push_back({field<std::string>(v, "name", src, p), field<double>(v, "psnr", src, p), field<double>(v, "ssim", src, p)});
  }
}

std::vector<std::string> names(const Scene& scene, const std::vector<int>& views) {
  std::vector<std::string> n;
  n.reserve(views.size());
  for (int v : views) n.push_back(scene.views.at(static_cast<std::size_t>(v)).name);
  return n;
}

}  // namespace

RunReport makeRunReport(const Scene& scene, const ActiveOptions& opt, const ActiveResult& r, const RunContext& c) {
  RunReport rep;
  rep.dataset = c.dataset;
  rep.method = toString(opt.method);
  rep.preset = c.preset;
  rep.seed = opt.seed;
  const ResidualOptions& ro = opt.trainer.residual;
  rep.options = {opt.interval,
                 opt.total_iterations,
                 opt.max_views,
                 opt.trainer.densify.max_gaussians,
                 opt.reset_after_add,
                 needsOf(opt.method).residual,
                 ro.alpha,
                 ro.beta,
                 toString(ro.ranking),
                 ro.sub_only,
                 toString(opt.prefilter.set),
                 encodingName(opt.prefilter.scoring),
                 toString(opt.prefilter.scoring.criterion),
                 opt.prefilter.keep_fraction};
  rep.psnr = r.test.psnr;
  rep.ssim = r.test.ssim;
  rep.ause = r.ause;
  rep.initial_views = names(scene, r.initial_views);
  rep.selected_views = names(scene, std::vector<int>(r.selected_views.begin() + static_cast<long>(r.initial_views.size()),
                                                     r.selected_views.end()));
  rep.selected_view_indices = r.selected_views;
  rep.seconds = r.total_seconds;
  rep.end_to_end_seconds = r.seconds;
  rep.gaussians = c.gaussians;
  rep.iterations = r.iterations;
  rep.phase_iterations = r.phase_iterations;
  rep.threads = c.threads;
  for (const ViewMetrics& m : r.test.views)
    rep.views.push_back({scene.views.at(static_cast<std::size_t>(m.view)).name, m.psnr, m.ssim});
  for (const SelectionLog& s : r.steps) rep.steps.push_back(stepReport(scene, s));
  auto fitReport = [&](const FinalFit& x) {
    FinalFitReport f{x.iterations, x.residual, x.test.psnr, x.test.ssim, {}, {}};
    for (const ViewMetrics& m : x.test.views) f.views.push_back({scene.views.at(static_cast<std::size_t>(m.view)).name, m.psnr, m.ssim});
    for (const ViewMetrics& m : x.path) f.path.push_back({scene.views.at(static_cast<std::size_t>(m.view)).name, m.psnr});
    return f;
  };
  if (r.final_fit) rep.final_fit = fitReport(*r.final_fit);
  if (r.final_fit_views) rep.final_fit_views = fitReport(*r.final_fit_views);
  rep.replay_of = c.replay_of;
  if (r.prefilter) rep.prefilter_regime = toJson(*r.prefilter);
  rep.frame = scene.frame;
  rep.background = backgroundJson(scene);
  return rep;
}

json toJson(const StepReport& s) {
  json e = {{"views_before", s.views_before}, {"progress_psnr", s.progress_psnr}, {"seconds", toJson(s.seconds)}};
  if (!s.selected.empty()) {
    e["selected"] = s.selected;
    e["candidates"] = s.candidates;
    e["scores"] = s.scores;
    if (!s.prefiltered.empty()) e["prefiltered"] = s.prefiltered;
    if (!s.fisher_scores.empty()) e["fisher_scores"] = s.fisher_scores;
    if (!s.new_surface.empty()) e["new_surface"] = s.new_surface;
    if (!s.view_distance.empty()) e["view_distance"] = s.view_distance;
  }
  return e;
}

StepReport stepReportFromJson(const json& j, const std::string& source, const std::string& path) {
  StepReport s;
  s.views_before = field<int>(j, "views_before", source, path);
  s.progress_psnr = field<double>(j, "progress_psnr", source, path);
  s.seconds = secondsFrom(jsonMember(j, "seconds", source, path), source, jsonPath(path, "seconds"));
  if (j.contains("selected")) {
    s.selected = field<std::string>(j, "selected", source, path);
    s.candidates = field<std::vector<std::string>>(j, "candidates", source, path);
    s.scores = field<std::vector<double>>(j, "scores", source, path);
    if (j.contains("prefiltered")) s.prefiltered = field<std::vector<std::string>>(j, "prefiltered", source, path);
    if (j.contains("fisher_scores")) s.fisher_scores = field<std::vector<double>>(j, "fisher_scores", source, path);
    if (j.contains("new_surface")) s.new_surface = field<std::vector<double>>(j, "new_surface", source, path);
    if (j.contains("view_distance")) s.view_distance = field<std::vector<double>>(j, "view_distance", source, path);
  }
  return s;
}

json toJson(const RunReport& r) {
  json j;
  j["dataset"] = r.dataset;
  j["method"] = r.method;
  j["seed"] = r.seed;
  j["preset"] = r.preset;
  const RunOptionsReport& o = r.options;
  j["options"] = {{"interval", o.interval},
                  {"total_iterations", o.total_iterations},
                  {"max_views", o.max_views},
                  {"max_gaussians", o.max_gaussians},
                  {"reset_after_add", o.reset_after_add},
                  {"residual", o.residual},
                  {"residual_alpha", o.residual_alpha},
                  {"residual_beta", o.residual_beta},
                  {"residual_ranking", o.residual_ranking},
                  {"residual_sub_only", o.residual_sub_only},
                  {"prefilter_set", o.prefilter_set},
                  {"prefilter_encoding", o.prefilter_encoding},
                  {"prefilter_score", o.prefilter_score},
                  {"prefilter_keep", o.prefilter_keep}};
  j["psnr"] = r.psnr;
  j["ssim"] = r.ssim;
  j["ause"] = r.ause ? json(*r.ause) : json(nullptr);
  j["initial_views"] = r.initial_views;
  j["selected_views"] = r.selected_views;
  j["selected_view_indices"] = r.selected_view_indices;
  j["seconds"] = toJson(r.seconds);
  j["seconds"]["end_to_end_this_process"] = r.end_to_end_seconds;
  j["gaussians"] = r.gaussians;
  j["iterations"] = r.iterations;
  if (r.phase_iterations) j["phase_iterations"] = *r.phase_iterations;
  j["threads"] = r.threads;
  for (const ViewReport& v : r.views) j["views"].push_back({{"name", v.name}, {"psnr", v.psnr}, {"ssim", v.ssim}});
  for (const StepReport& s : r.steps) j["steps"].push_back(toJson(s));
  auto fitJson = [](const FinalFitReport& x) {
    json f = {{"iterations", x.iterations}, {"residual", x.residual}, {"psnr", x.psnr}, {"ssim", x.ssim}};
    for (const ViewReport& v : x.views) f["views"].push_back({{"name", v.name}, {"psnr", v.psnr}, {"ssim", v.ssim}});
    for (const PathViewReport& v : x.path) f["path"].push_back({{"name", v.name}, {"psnr", v.psnr}});
    return f;
  };
  if (r.final_fit) j["final_fit"] = fitJson(*r.final_fit);
  if (r.final_fit_views) j["final_fit_views"] = fitJson(*r.final_fit_views);
  if (!r.replay_of.empty()) j["replay_of"] = r.replay_of;
  if (r.prefilter_regime) j["prefilter_regime"] = *r.prefilter_regime;
  if (r.frame) j["frame"] = toJson(*r.frame);
  if (r.background) j["background"] = *r.background;
  return j;
}

RunReport runReportFromJson(const json& j, const std::string& src) {
  if (!j.is_object()) throw InputError(src, "json", "expected an object");
  RunReport r;
  r.dataset = field<std::string>(j, "dataset", src, "");
  r.method = field<std::string>(j, "method", src, "");
  r.seed = field<std::uint64_t>(j, "seed", src, "");
  r.preset = field<std::string>(j, "preset", src, "");
  const json& o = jsonMember(j, "options", src, "");
  RunOptionsReport& ro = r.options;
  ro.interval = field<int>(o, "interval", src, "options");
  ro.total_iterations = field<int>(o, "total_iterations", src, "options");
  ro.max_views = field<int>(o, "max_views", src, "options");
  ro.max_gaussians = field<std::size_t>(o, "max_gaussians", src, "options");
  ro.reset_after_add = field<bool>(o, "reset_after_add", src, "options");
  ro.residual = field<bool>(o, "residual", src, "options");
  ro.residual_alpha = field<double>(o, "residual_alpha", src, "options");
  ro.residual_beta = field<double>(o, "residual_beta", src, "options");
  ro.residual_ranking = field<std::string>(o, "residual_ranking", src, "options");
  ro.residual_sub_only = field<bool>(o, "residual_sub_only", src, "options");
  ro.prefilter_set = field<std::string>(o, "prefilter_set", src, "options");
  ro.prefilter_encoding = field<std::string>(o, "prefilter_encoding", src, "options");
  ro.prefilter_score = field<std::string>(o, "prefilter_score", src, "options");
  ro.prefilter_keep = field<double>(o, "prefilter_keep", src, "options");
  r.psnr = field<double>(j, "psnr", src, "");
  r.ssim = field<double>(j, "ssim", src, "");
  if (!j.contains("ause")) throw InputError(src, "ause", "missing (null when there is no depth)");
  if (!j["ause"].is_null()) r.ause = field<double>(j, "ause", src, "");
  r.initial_views = field<std::vector<std::string>>(j, "initial_views", src, "");
  r.selected_views = field<std::vector<std::string>>(j, "selected_views", src, "");
  r.selected_view_indices = field<std::vector<int>>(j, "selected_view_indices", src, "");
  r.seconds = secondsFrom(jsonMember(j, "seconds", src, ""), src, "seconds");
  r.end_to_end_seconds = field<double>(j["seconds"], "end_to_end_this_process", src, "seconds");
  r.gaussians = field<std::size_t>(j, "gaussians", src, "");
  r.iterations = field<int>(j, "iterations", src, "");
  if (j.contains("phase_iterations")) r.phase_iterations = field<std::vector<int>>(j, "phase_iterations", src, "");
  r.threads = field<int>(j, "threads", src, "");
  readViews(j, src, "views", r.views);
  const json& steps = jsonArray(jsonMember(j, "steps", src, ""), src, "steps");
  for (std::size_t i = 0; i < steps.size(); ++i) r.steps.push_back(stepReportFromJson(steps[i], src, jsonPath("steps", i)));
  auto readFit = [&](const char* name) {
    const json& f = j[name];
    FinalFitReport ff;
    ff.iterations = field<int>(f, "iterations", src, name);
    if (f.contains("residual")) ff.residual = field<bool>(f, "residual", src, name);
    ff.psnr = field<double>(f, "psnr", src, name);
    ff.ssim = field<double>(f, "ssim", src, name);
    readViews(f, src, std::string(name) + ".views", ff.views);
    if (f.contains("path")) {
      const std::string at = std::string(name) + ".path";
      const json& path = jsonArray(f["path"], src, at);
      for (std::size_t i = 0; i < path.size(); ++i)
        ff.path.push_back({field<std::string>(path[i], "name", src, jsonPath(at, i)), field<double>(path[i], "psnr", src, jsonPath(at, i))});
    }
    return ff;
  };
  if (j.contains("final_fit")) r.final_fit = readFit("final_fit");
  if (j.contains("final_fit_views")) r.final_fit_views = readFit("final_fit_views");
  else if (r.final_fit && !r.final_fit->residual) r.final_fit_views = r.final_fit;  // written before it was recorded
  if (j.contains("replay_of")) r.replay_of = field<std::string>(j, "replay_of", src, "");
  if (j.contains("prefilter_regime")) r.prefilter_regime = jsonObject(j["prefilter_regime"], src, "prefilter_regime");
  if (j.contains("frame")) r.frame = sceneFrameFromJson(j["frame"], src, "frame");
  if (j.contains("background")) r.background = jsonObject(j["background"], src, "background");
  return r;
}

StepReport stepReport(const Scene& scene, const SelectionLog& log) {
  StepReport s;
  s.views_before = log.views_before;
  s.progress_psnr = log.progress_psnr;
  s.seconds = log.seconds;
  if (log.selected >= 0) {
    s.selected = scene.views.at(static_cast<std::size_t>(log.selected)).name;
    s.candidates = names(scene, log.candidates);
    s.scores = log.scores;
    s.prefiltered = names(scene, log.prefiltered);
    s.fisher_scores = log.fisher_scores;
    s.new_surface = log.new_surface;
    s.view_distance = log.view_distance;
  }
  return s;
}

SelectionLog selectionLog(const Scene& scene, const StepReport& step, const std::string& source) {
  std::map<std::string, int> by_name;
  for (int v : scene.train) by_name.emplace(scene.views.at(static_cast<std::size_t>(v)).name, v);
  auto index = [&](const std::string& name) {
    auto it = by_name.find(name);
    if (it == by_name.end()) throw InputError(source, "steps", "'" + name + "' is not a train view of this dataset");
    return it->second;
  };
  auto indices = [&](const std::vector<std::string>& n) {
    std::vector<int> v;
    for (const auto& s : n) v.push_back(index(s));
    return v;
  };
  SelectionLog l;
  l.views_before = step.views_before;
  l.progress_psnr = step.progress_psnr;
  l.seconds = step.seconds;
  l.selected = step.selected.empty() ? -1 : index(step.selected);
  l.candidates = indices(step.candidates);
  l.scores = step.scores;
  l.prefiltered = indices(step.prefiltered);
  l.fisher_scores = step.fisher_scores;
  l.new_surface = step.new_surface;
  l.view_distance = step.view_distance;
  return l;
}

}  // namespace saresgs

namespace saresgs {

std::vector<int> replaySequence(const Scene& scene, const RunReport& r, const std::string& source) {
  std::map<std::string, int> by_name;
  for (int v : scene.train) by_name.emplace(scene.views.at(static_cast<std::size_t>(v)).name, v);
  std::vector<int> seq;
  auto add = [&](const std::vector<std::string>& names, const char* field) {
    for (const std::string& n : names) {
      auto it = by_name.find(n);
      if (it == by_name.end())
        throw InputError(source, field, "'" + n + "' is not a train view of this dataset (a run of another dataset?)");
      seq.push_back(it->second);
    }
  };
  add(r.initial_views, "initial_views");
  add(r.selected_views, "selected_views");
  return seq;
}

}  // namespace saresgs
