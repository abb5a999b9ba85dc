#include "nbv/step_report.h"

#include <map>

#include "geometry/error.h"
#include "geometry/io/json_file.h"
#include "nbv/report_json.h"

namespace saresgs {

using json = nlohmann::json;
using report_json::field;
using report_json::names;

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
