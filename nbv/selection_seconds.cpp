#include "nbv/selection_seconds.h"

namespace saresgs {

SelectionSeconds& SelectionSeconds::operator+=(const SelectionSeconds& o) {
  lifting += o.lifting;
  triangulation += o.triangulation;
  prefilter += o.prefilter;
  fisher += o.fisher;
  training += o.training;
  exhaustive_fisher += o.exhaustive_fisher;
  return *this;
}

nlohmann::json toJson(const SelectionSeconds& s) {
  return {{"lifting", s.lifting},   {"triangulation", s.triangulation}, {"prefilter", s.prefilter},
          {"fisher", s.fisher},     {"training", s.training},           {"exhaustive_fisher", s.exhaustive_fisher}};
}

SelectionSeconds secondsFrom(const nlohmann::json& j) {
  SelectionSeconds s;
  s.lifting = j.at("lifting").get<double>();
  s.triangulation = j.at("triangulation").get<double>();
  s.prefilter = j.at("prefilter").get<double>();
  s.fisher = j.at("fisher").get<double>();
  s.training = j.at("training").get<double>();
  s.exhaustive_fisher = j.at("exhaustive_fisher").get<double>();
  return s;
}

}  // namespace saresgs
