#include "nbv/active_options.h"

#include <array>
#include <stdexcept>
#include <string>

#include "geometry/enum_names.h"

namespace saresgs {

bool finalFitIsResidual(const ActiveOptions& o) { return needsOf(o.method).residual || o.final_residual; }

TrainerOptions finalFitOptions(const ActiveOptions& o, bool method_training) {
  TrainerOptions t = o.final_trainer;
  t.seed = o.seed;
  t.residual = o.trainer.residual;
  t.residual.enabled = method_training && finalFitIsResidual(o);
  return t;
}

const char* toString(ActivePhase p) {
  static constexpr std::array<const char*, 8> kNames{"training",  "lifting",           "prefilter",
                                                     "Fisher",    "exhaustive Fisher", "final evaluation",
                                                     "final fit", "plain refit"};
  return enumName(p, kNames);
}

bool usesKmedianGate(const Scene& scene, const ActiveOptions& o) {
  switch (o.method) {
    case Method::kKmedianFisher:
      return true;
    case Method::kFvsFisher:
      return false;
    case Method::kAdaptive:
      return captureClustering(scene) > o.adaptive_clustering;
    default:
      throw std::invalid_argument(std::string("usesKmedianGate: ") + toString(o.method) + " has no gate");
  }
}

}  // namespace saresgs
