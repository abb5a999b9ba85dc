#include "nbv/active_settings.h"

#include <limits>

#include "nbv/method.h"
#include "nbv/prefilter_options.h"
#include "nbv/preset.h"
#include "splat/train/residual.h"

namespace saresgs {

namespace {

using S = ActiveSettings;
constexpr double kInf = std::numeric_limits<double>::infinity();

std::vector<ActiveSettingField> makeFields() {
  std::vector<ActiveSettingField> f;
  auto add = [&](std::string name, SettingMember<S> m, std::string help) -> ActiveSettingField& {
    return addSetting(f, std::move(name), m, std::move(help));
  };
  auto range = [](ActiveSettingField& r, double lo, double hi) { r.lo = lo, r.hi = hi; };
  auto shown = [](ActiveSettingField& r, std::vector<std::string> choices = {}) {
    r.show_default = true;
    r.choices = std::move(choices);
  };
  shown(add("method", &S::method, methodChoices()), methodNames());
  range(add("seed", &S::seed, "Random seed"), 0, kInf);
  f.back().show_default = true;
  shown(add("preset", &S::preset, "quick | paper"));
  range(add("max_views", &S::max_views, "Views at the end (default 20)"), 1, kInf);
  range(add("interval", &S::interval, "Iterations per view held (preset's by default)"), 1, kInf);
  range(add("min_iterations", &S::min_iterations,
            "Least total iterations of the loop: the last phase trains what is left and never less than views x "
            "interval, so more may run (preset's by default; results.json: iterations, phase_iterations)"),
        1, kInf);
  range(add("final_iterations", &S::final_iterations,
            "Final fit: a fresh model trained on the chosen views for N iterations (0: none; preset's by default)"),
        0, kInf);
  add("plain_refit", &S::plain_refit,
      "Methods with their own training (sa-resgs, resgs): leave out the plain 3DGS refit of the chosen views that "
      "judges selection apart from training (as long as the final fit itself)");
  add("final_residual", &S::final_residual,
      "Final fit with the paper's residual supervision whatever the method (the loop and its selection unchanged); a "
      "plain 3DGS refit of the same views follows unless --no-plain-refit");
  range(add("max_gaussians", &S::max_gaussians, "Cap on the model size (0: none; preset's by default)"), 0, 1e9);
  range(add("residual_beta", &S::residual_beta, "Uncertain fraction of the residual subset (default 0.1)"), 0, 1);
  add("residual_ranking", &S::residual_ranking, "Uncertainty ranking: both | opacity | scale | random (default both)")
      .choices = {"both", "opacity", "scale", "random"};
  add("residual_sub_only", &S::residual_sub_only, "Ablation: subset loss only, no full-render loss");
  add("continue_training", &S::continue_training,
      "Keep training the same model after each addition instead of resetting it");
  shown(add("fvs_metric", &S::fvs_metric, "euclidean | great-circle"), {"euclidean", "great-circle"});
  add("fisher_lambda", &S::fisher_lambda, "Fisher damping lambda (> 0; default 1e-06)").positive = true;
  shown(add("prefilter_set", &S::prefilter_set, "frustum | visible"));
  shown(add("prefilter_encoding", &S::prefilter_encoding,
            "hash:auto (the smallest 2^K, K in 11..19, with load <= 0.5) | hash:K (11..19) | exact"));
  shown(add("prefilter_scene", &S::prefilter_scene,
            "indoor (5 SfM points per occupied voxel, grid 32) | outdoor (2, grid 64) | auto (a built-in scene's "
            "layout says; outdoor otherwise)"),
        {"auto", "indoor", "outdoor"});
  shown(add("prefilter_score", &S::prefilter_score, "xor | new"));
  shown(add("prefilter_lifting", &S::prefilter_lifting,
            "SA-Point lifting: flow (DIS + epipolar refinement) | depth (the trainer's rendered depth) | oracle (the "
            "dataset's ground-truth depth maps)"));
  range(add("prefilter_keep", &S::prefilter_keep, "Fraction kept for Fisher (default 0.2)"), 0, 1);
  range(add("hybrid_weight", &S::hybrid_weight,
            "hybrid: share of the coverage evidence against Fisher's, in [0, 1] (default 0.5)"),
        0, 1);
  shown(add("hybrid_fisher", &S::hybrid_fisher, "hybrid: Fisher criterion combined, trace | logdet"),
        {"trace", "logdet"});
  shown(add("hybrid_coverage", &S::hybrid_coverage,
            "hybrid: second evidence, surface (Embree-visible SfM surface no held view saw) | views (distance to the "
            "nearest held camera) | facility (the facility-location gain over the train views, by the overlap of "
            "their visible surface)"),
        {"surface", "views", "facility"});
  range(add("path_variance_kappa", &S::path_variance_kappa,
            "path-variance: each parameter group's damping, as a multiple of the median of its nonzero held "
            "information (0: --fisher-lambda alone; default 0.01)"),
        0, 1e6);
  range(add("gate_keep", &S::gate_keep,
            "kmedian-fisher, fvs-fisher, adaptive: fraction of the candidates, best by the gate's spread score "
            "(k-median gain or distance to the nearest held view), that Fisher ranks (default 0.2)"),
        0, 1);
  range(add("adaptive_clustering", &S::adaptive_clustering,
            "adaptive: a capture whose clustering (the coefficient of variation of each train camera's distance to "
            "its 5th nearest; `saresgs info` prints it) exceeds this gets the k-median gate, any other the "
            "farthest-view gate (default 0.7)"),
        0, 1e6);
  add("time_exhaustive_fisher", &S::time_exhaustive_fisher, "Also time Fisher over all candidates");
  range(add("threads", &S::threads, "Threads (0: all cores)"), 0, 1024);
  return f;
}

}  // namespace

const std::vector<ActiveSettingField>& activeSettingFields() {
  static const std::vector<ActiveSettingField> fields = makeFields();
  return fields;
}

ActiveOptions activeOptionsFrom(const ActiveSettings& s, const std::string& dataset, SettingNaming naming) {
  ActiveOptions o = presetOptions(parsePreset(s.preset));
  o.method = parseMethod(s.method);
  o.seed = s.seed;
  o.trainer.raster.execution.threads = s.threads;
  o.final_trainer.raster.execution.threads = s.threads;
  if (s.max_views) o.max_views = *s.max_views;
  if (s.interval) o.interval = *s.interval;
  if (s.min_iterations) o.total_iterations = *s.min_iterations;
  if (s.final_iterations) o.final_iterations = *s.final_iterations;
  if (s.max_gaussians) o.trainer.densify.max_gaussians = o.final_trainer.densify.max_gaussians = *s.max_gaussians;
  o.plain_refit = s.plain_refit;
  o.final_residual = s.final_residual;
  if (s.fisher_lambda) o.fisher_lambda = *s.fisher_lambda;
  if (s.gate_keep) o.gate_keep = *s.gate_keep;
  if (s.path_variance_kappa) o.path_variance_kappa = *s.path_variance_kappa;
  if (s.adaptive_clustering) o.adaptive_clustering = *s.adaptive_clustering;
  if (s.hybrid_weight) o.hybrid_weight = *s.hybrid_weight;
  o.reset_after_add = !s.continue_training;
  o.time_exhaustive_fisher = s.time_exhaustive_fisher;
  o.fvs_metric = s.fvs_metric == "great-circle" ? ViewDistance::kGreatCircle : ViewDistance::kEuclidean;
  if (s.residual_beta) o.trainer.residual.beta = *s.residual_beta;
  if (s.residual_ranking) o.trainer.residual.ranking = parseUncertaintyRanking(*s.residual_ranking);
  if (s.residual_sub_only) o.trainer.residual.sub_only = true;
  const PrefilterFlags flags{s.prefilter_set, s.prefilter_encoding, s.prefilter_score, s.prefilter_lifting,
                             s.prefilter_scene};
  o.prefilter =
      parsePrefilterFlags(flags, o.prefilter, naming == SettingNaming::kFlag ? "--prefilter-" : "prefilter_", dataset);
  if (s.prefilter_keep) o.prefilter.keep_fraction = *s.prefilter_keep;
  o.hybrid_criterion = s.hybrid_fisher == "trace" ? FisherCriterion::kTrace : FisherCriterion::kLogDet;
  o.hybrid_coverage = s.hybrid_coverage == "views"      ? HybridCoverage::kViewDistance
                      : s.hybrid_coverage == "facility" ? HybridCoverage::kFacility
                                                        : HybridCoverage::kSurface;
  return o;
}

}  // namespace saresgs
