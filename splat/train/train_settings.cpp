#include "splat/train/train_settings.h"

#include "splat/train/residual.h"
#include "splat/train/schedule.h"

namespace saresgs {

namespace {

using S = TrainSettings;

std::vector<TrainSettingField> makeFields() {
  std::vector<TrainSettingField> f;
  auto add = [&](std::string name, SettingMember<S> m, std::string help, double lo, double hi,
                 bool shown = true) -> TrainSettingField& {
    TrainSettingField& r = addSetting(f, std::move(name), m, std::move(help));
    r.lo = lo, r.hi = hi;
    r.show_default = shown;
    return r;
  };
  constexpr double kInf = std::numeric_limits<double>::infinity();
  add("max_sh_degree", &S::max_sh_degree, "Maximum SH degree", 0, 3).flag = "--sh-degree";
  add("seed", &S::seed, "Random seed", 0, kInf);
  add("threads", &S::threads, "Threads (0: all cores)", 0, 1024, false);
  add("densify_until", &S::densify_until, "Last densification iteration", 0, kInf);
  add("max_gaussians", &S::max_gaussians, "Cap on the model size (0: none)", 0, 1e9);
  add("random_init", &S::random_init, "Random points when the dataset has none", 1, 1e7);
  add("residual", &S::residual, "Add SA-ResGS residual supervision", -kInf, kInf, false);
  add("schedule_scale", &S::schedule_scale,
      "Scale the densification, opacity-reset and SH schedules (the quick preset's is 0.25)", 1e-4, 1e4);
  add("residual_alpha", &S::residual_alpha, "Random fraction of G_sub", 0, 1);
  add("residual_beta", &S::residual_beta, "Uncertain fraction of G_sub", 0, 1);
  add("residual_ranking", &S::residual_ranking, "both | opacity | scale | random", -kInf, kInf).choices = {
      "both", "opacity", "scale", "random"};
  return f;
}

}  // namespace

const std::vector<TrainSettingField>& trainSettingFields() {
  static const std::vector<TrainSettingField> fields = makeFields();
  return fields;
}

TrainerOptions trainerOptionsFrom(const TrainSettings& s) {
  TrainerOptions o;
  o.seed = s.seed;
  o.max_sh_degree = s.max_sh_degree;
  o.densify.until_iter = s.densify_until;
  o.densify.max_gaussians = s.max_gaussians;
  o.random_init_points = s.random_init;
  o.residual.enabled = s.residual;
  o.residual.alpha = s.residual_alpha;
  o.residual.beta = s.residual_beta;
  o.residual.ranking = parseUncertaintyRanking(s.residual_ranking);
  o.raster.execution.threads = s.threads;
  if (s.schedule_scale != 1.0) o = scaledSchedule(o, s.schedule_scale);
  return o;
}

}  // namespace saresgs
