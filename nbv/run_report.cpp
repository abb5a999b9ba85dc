#include "nbv/run_report.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <map>
#include <type_traits>

#include "geometry/error.h"
#include "geometry/io/json_file.h"
#include "geometry/scene/cameras_json.h"
#include "nbv/report_json.h"
#include "splat/train/residual.h"

namespace saresgs {

namespace {

using json = nlohmann::json;
using report_json::field;
using report_json::names;

// The optional per-view array `j["views"]` (named `path` in messages).
void readViews(const json& j, const std::string& src, const std::string& path, std::vector<ViewReport>& out) {
  if (!j.contains("views")) return;
  jsonArray(j["views"], src, path);
  for (std::size_t i = 0; i < j["views"].size(); ++i) {
    const std::string p = jsonPath(path, i);
    const json& v = j["views"][i];
    out.push_back(
        {field<std::string>(v, "name", src, p), field<double>(v, "psnr", src, p), field<double>(v, "ssim", src, p)});
  }
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
  rep.selected_views = names(
      scene,
      std::vector<int>(r.selected_views.begin() + static_cast<long>(r.initial_views.size()), r.selected_views.end()));
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
    for (const ViewMetrics& m : x.test.views)
      f.views.push_back({scene.views.at(static_cast<std::size_t>(m.view)).name, m.psnr, m.ssim});
    for (const ViewMetrics& m : x.path)
      f.path.push_back({scene.views.at(static_cast<std::size_t>(m.view)).name, m.psnr});
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
  for (std::size_t i = 0; i < steps.size(); ++i)
    r.steps.push_back(stepReportFromJson(steps[i], src, jsonPath("steps", i)));
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
        ff.path.push_back({field<std::string>(path[i], "name", src, jsonPath(at, i)),
                           field<double>(path[i], "psnr", src, jsonPath(at, i))});
    }
    return ff;
  };
  if (j.contains("final_fit")) r.final_fit = readFit("final_fit");
  if (j.contains("final_fit_views"))
    r.final_fit_views = readFit("final_fit_views");
  else if (r.final_fit && !r.final_fit->residual)
    r.final_fit_views = r.final_fit;  // written before it was recorded
  if (j.contains("replay_of")) r.replay_of = field<std::string>(j, "replay_of", src, "");
  if (j.contains("prefilter_regime")) r.prefilter_regime = jsonObject(j["prefilter_regime"], src, "prefilter_regime");
  if (j.contains("frame")) r.frame = sceneFrameFromJson(j["frame"], src, "frame");
  if (j.contains("background")) r.background = jsonObject(j["background"], src, "background");
  return r;
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
