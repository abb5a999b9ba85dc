#include "nbv/selection_seconds.h"

#include <limits>

#include "geometry/io/json_file.h"

namespace saresgs {

SelectionSeconds& SelectionSeconds::operator+=(const SelectionSeconds& o) {
  lifting += o.lifting;
  triangulation += o.triangulation;
  prefilter += o.prefilter;
  fisher += o.fisher;
  training += o.training;
  exhaustive_fisher += o.exhaustive_fisher;
  coverage += o.coverage;
  return *this;
}

nlohmann::json toJson(const SelectionSeconds& s) {
  return {{"lifting", s.lifting},  {"triangulation", s.triangulation}, {"prefilter", s.prefilter},
          {"fisher", s.fisher},    {"training", s.training},           {"exhaustive_fisher", s.exhaustive_fisher},
          {"coverage", s.coverage}};
}

SelectionSeconds secondsFrom(const nlohmann::json& j, const std::string& file, const std::string& field) {
  SelectionSeconds s;
  auto stage = [&](const char* key) {
    return jsonNumberIn(jsonMember(j, key, file, field), file, jsonPath(field, key), 0,
                        std::numeric_limits<double>::max());
  };
  s.lifting = stage("lifting");
  s.triangulation = stage("triangulation");
  s.prefilter = stage("prefilter");
  s.fisher = stage("fisher");
  s.training = stage("training");
  s.exhaustive_fisher = stage("exhaustive_fisher");
  if (j.is_object() && j.contains("coverage")) s.coverage = stage("coverage");
  return s;
}

}  // namespace saresgs
