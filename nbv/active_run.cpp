#include "nbv/active_run.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "geometry/error.h"
#include "geometry/io/atomic_file.h"
#include "geometry/io/json_file.h"
#include "nbv/ause.h"
#include "nbv/initial_views.h"
#include "splat/fisher.h"

namespace saresgs {

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

void addSeconds(SelectionSeconds& a, const SelectionSeconds& b) {
  a.lifting += b.lifting;
  a.triangulation += b.triangulation;
  a.prefilter += b.prefilter;
  a.fisher += b.fisher;
  a.training += b.training;
  a.exhaustive_fisher += b.exhaustive_fisher;
}

}  // namespace

SelectionSeconds secondsFrom(const nlohmann::json& j) {
  SelectionSeconds s;
  s.lifting = j.at("lifting");
  s.triangulation = j.at("triangulation");
  s.prefilter = j.at("prefilter");
  s.fisher = j.at("fisher");
  s.training = j.at("training");
  s.exhaustive_fisher = j.at("exhaustive_fisher");
  return s;
}

nlohmann::json toJson(const SelectionSeconds& s) {
  return {{"lifting", s.lifting},   {"triangulation", s.triangulation}, {"prefilter", s.prefilter},
          {"fisher", s.fisher},     {"training", s.training},           {"exhaustive_fisher", s.exhaustive_fisher}};
}

Method parseMethod(const std::string& s) {
  for (Method m : {Method::kRandom, Method::kFvs, Method::kFisher, Method::kCoverage, Method::kSaHash, Method::kSaResgs,
                   Method::kResgs})
    if (s == toString(m)) return m;
  throw std::invalid_argument("method '" + s + "': expected random, fvs, fisher, coverage, sa-hash, sa-resgs or resgs");
}

const char* toString(Method m) {
  switch (m) {
    case Method::kRandom: return "random";
    case Method::kFvs: return "fvs";
    case Method::kFisher: return "fisher";
    case Method::kCoverage: return "coverage";
    case Method::kSaHash: return "sa-hash";
    case Method::kSaResgs: return "sa-resgs";
    case Method::kResgs: return "resgs";
  }
  return "?";
}

MethodNeeds needsOf(Method m) {
  switch (m) {
    case Method::kRandom:
    case Method::kFvs: return {false, false, false};
    case Method::kFisher: return {true, false, false};
    case Method::kCoverage: return {false, true, false};
    case Method::kSaHash: return {true, true, false};
    case Method::kSaResgs: return {true, true, true};
    case Method::kResgs: return {true, false, true};
  }
  return {};
}

void applyPreset(const std::string& name, ActiveOptions& o) {
  if (name == "paper") {
    o.interval = 100;
    o.total_iterations = 20000;
    return;
  }
  if (name == "quick") {
    // Sized so that a 20-view run on a 256x192 scene takes at most ~10 minutes on 2 cores:
    // 25 iterations per view held (the paper's 100), 5000 in all, densification and the
    // SH schedule scaled alike. A 20-view sa-resgs run on room360 trained at ~10 it/s
    // with selection included (40 per view, 8000 in all, measured: over 13 minutes).
    o.interval = 25;
    o.total_iterations = 5000;
    o.trainer.densify.from_iter = 125;
    o.trainer.densify.interval = 25;
    o.trainer.densify.opacity_reset_interval = 750;
    o.trainer.densify.until_iter = 3750;
    o.trainer.densify.min_iterations_after_reset = 125;
    o.trainer.sh_interval = 250;
    // Densification's 2e-4 threshold is sized for ~800-pixel images; at 256x192 an
    // unbounded run grew room360 to 215k Gaussians (over 4 per pixel), which made training
    // and Fisher scoring the whole cost. The cap keeps the model at a size the images
    // can constrain.
    o.trainer.densify.max_gaussians = 40000;
    return;
  }
  throw std::invalid_argument("preset '" + name + "': expected paper or quick");
}

ActiveRun::ActiveRun(const Scene& scene, const ActiveOptions& opt, std::string checkpoint)
    : scene_(scene), opt_(opt), checkpoint_(std::move(checkpoint)), rng_(opt.seed) {
  if (scene_.train.empty()) throw std::invalid_argument("ActiveRun: the scene has no train views");
  if (opt_.initial_views < 1 || opt_.max_views < opt_.initial_views)
    throw std::invalid_argument("ActiveRun: need 1 <= initial views <= max views");
  const MethodNeeds needs = needsOf(opt_.method);
  TrainerOptions to = opt_.trainer;
  to.seed = opt_.seed;
  to.residual.enabled = needs.residual;
  trainer_ = std::make_unique<Trainer>(scene_, to);
  if (needs.coverage) prefilter_ = makeCoveragePrefilter(scene_, opt_.prefilter, opt_.seed);
}

int ActiveRun::selectNext(SelectionLog& log) {
  std::vector<int> candidates;
  for (int v : scene_.train)
    if (std::find(selected_.begin(), selected_.end(), v) == selected_.end()) candidates.push_back(v);
  log.views_before = static_cast<int>(selected_.size());
  const MethodNeeds needs = needsOf(opt_.method);
  std::vector<int> pool = candidates;
  if (needs.coverage) {
    std::vector<int> fresh(selected_.begin() + observed_upto_, selected_.end());
    prefilter_->observe(
        fresh, [this](const Camera& c) { return trainer_->render(c).rgb; },
        [this](const Camera& c) { return trainer_->render(c).depth; }, log.seconds);
    observed_upto_ = static_cast<int>(selected_.size());
    const std::vector<double> cov = prefilter_->score(candidates, log.seconds);
    if (!needs.fisher) {
      log.candidates = candidates;
      log.scores = cov;
      return candidates[argmaxScore(cov, candidates)];
    }
    const auto t0 = Clock::now();
    pool = topFraction(cov, candidates, opt_.prefilter.keep_fraction);
    log.seconds.prefilter += since(t0);
    log.prefiltered = pool;
  }
  switch (opt_.method) {
    case Method::kRandom: {
      log.candidates = candidates;
      return selectRandom(candidates, rng_);
    }
    case Method::kFvs: {
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (int v : scene_.train) c += scene_.views[static_cast<std::size_t>(v)].camera.center();
      c /= static_cast<double>(scene_.train.size());
      log.candidates = candidates;
      log.scores = farthestViewScores(scene_, selected_, candidates, opt_.fvs_metric, c);
      return candidates[argmaxScore(log.scores, candidates)];
    }
    default: break;
  }
  // Fisher on the pool (all candidates, or the prefiltered ones).
  const RasterSettings s = trainer_->rasterSettings();
  auto t0 = Clock::now();
  log.candidates = pool;
  log.scores = fisherScores(trainer_->gaussians(), s, scene_, selected_, pool, opt_.fisher_lambda);
  log.seconds.fisher += since(t0);
  if (needs.coverage && opt_.time_exhaustive_fisher) {
    t0 = Clock::now();
    (void)fisherScores(trainer_->gaussians(), s, scene_, selected_, candidates, opt_.fisher_lambda);
    log.seconds.exhaustive_fisher += since(t0);
  }
  return pool[argmaxScore(log.scores, pool)];
}

ActiveResult ActiveRun::run(const std::function<void(const ActiveProgress&)>& progress) {
  const auto start = Clock::now();
  if (!loadCheckpoint()) {
    std::vector<Eigen::Vector3d> centers;
    for (int v : scene_.train) centers.push_back(scene_.views[static_cast<std::size_t>(v)].camera.center());
    for (int i : farthestPointSampling(centers, opt_.initial_views, 0)) initial_.push_back(scene_.train[static_cast<std::size_t>(i)]);
    selected_ = initial_;
  }
  std::vector<int> progress_views;
  for (std::size_t i = 0; i < scene_.test.size() && static_cast<int>(i) < opt_.progress_test_views; ++i)
    progress_views.push_back(scene_.test[i * scene_.test.size() / std::min<std::size_t>(scene_.test.size(), opt_.progress_test_views)]);
  double last_psnr = 0;
  while (true) {
    const int k = static_cast<int>(selected_.size());
    const bool last = k >= opt_.max_views || k >= static_cast<int>(scene_.train.size());
    const int phase = last ? std::max(opt_.total_iterations - iterations_done_, k * opt_.interval) : k * opt_.interval;
    if (opt_.reset_after_add) trainer_->reset();
    const auto t0 = Clock::now();
    trainer_->train(selected_, phase, [&](const TrainProgress& p) {
      if (progress)
        progress({k, opt_.max_views, iterations_done_ + p.done, std::max(opt_.total_iterations, iterations_done_ + phase),
                  p.loss_ema, last_psnr, p.gaussians});
    });
    const double train_s = since(t0);
    iterations_done_ += phase;
    if (!progress_views.empty()) last_psnr = trainer_->evaluate(progress_views).psnr;
    if (last) {
      // The final phase's training belongs to no selection; a log entry without a
      // selected view keeps it in the totals.
      SelectionSeconds tail;
      tail.training = train_s;
      steps_.push_back({k, -1, {}, {}, {}, tail, last_psnr});
      break;
    }
    SelectionLog log;
    log.seconds.training = train_s;
    log.progress_psnr = last_psnr;
    const int next = selectNext(log);
    log.selected = next;
    selected_.push_back(next);
    steps_.push_back(std::move(log));
    saveCheckpoint();
  }
  ActiveResult r;
  r.initial_views = initial_;
  r.selected_views = selected_;
  r.steps = steps_;
  for (const auto& s : steps_) addSeconds(r.total_seconds, s.seconds);
  r.iterations = iterations_done_;
  r.test = trainer_->evaluate(scene_.test.empty() ? scene_.train : scene_.test);
  r.ause = depthAuse(*trainer_, selected_, scene_.test.empty() ? scene_.train : scene_.test, opt_.fisher_lambda);
  r.seconds = since(start);
  return r;
}

void ActiveRun::saveCheckpoint() const {
  if (checkpoint_.empty()) return;
  const std::string tag = std::to_string(selected_.size());
  trainer_->saveCheckpoint(checkpoint_ + ".trainer." + tag);
  if (prefilter_) writeFileAtomic(checkpoint_ + ".prefilter." + tag, prefilter_->save());
  nlohmann::json j;
  j["format"] = "saresgs-active-checkpoint-1";
  j["method"] = toString(opt_.method);
  j["seed"] = opt_.seed;
  j["views"] = scene_.views.size();
  j["initial"] = initial_;
  j["selected"] = selected_;
  j["iterations_done"] = iterations_done_;
  j["observed_upto"] = observed_upto_;
  std::ostringstream rs;
  rs << rng_;
  j["rng"] = rs.str();
  j["tag"] = tag;
  for (const SelectionLog& s : steps_)
    j["steps"].push_back({{"views_before", s.views_before}, {"selected", s.selected}, {"candidates", s.candidates},
                          {"scores", s.scores}, {"prefiltered", s.prefiltered}, {"seconds", toJson(s.seconds)},
                          {"progress_psnr", s.progress_psnr}});
  writeFileAtomic(checkpoint_, j.dump() + "\n");
  // Older companions are obsolete once the state that names the new ones is in place.
  const int previous = static_cast<int>(selected_.size()) - 1;
  std::error_code ec;
  std::filesystem::remove(checkpoint_ + ".trainer." + std::to_string(previous), ec);
  std::filesystem::remove(checkpoint_ + ".prefilter." + std::to_string(previous), ec);
}

bool ActiveRun::loadCheckpoint() {
  if (checkpoint_.empty() || !std::filesystem::exists(checkpoint_)) return false;
  const nlohmann::json j = readJsonFile(checkpoint_);
  auto field = [&](const char* name) -> const nlohmann::json& {
    if (!j.contains(name)) throw InputError(checkpoint_, name, "missing");
    return j[name];
  };
  if (field("format") != "saresgs-active-checkpoint-1") throw InputError(checkpoint_, "format", "not an active-run checkpoint");
  if (field("method") != toString(opt_.method))
    throw InputError(checkpoint_, "method", "written by method " + j["method"].dump() + ", this run is " + toString(opt_.method));
  if (field("seed") != opt_.seed) throw InputError(checkpoint_, "seed", "written with seed " + j["seed"].dump());
  if (field("views") != scene_.views.size()) throw InputError(checkpoint_, "views", "written for another scene");
  try {
    initial_ = field("initial").get<std::vector<int>>();
    selected_ = field("selected").get<std::vector<int>>();
    iterations_done_ = field("iterations_done");
    observed_upto_ = field("observed_upto");
    std::istringstream rs(field("rng").get<std::string>());
    rs >> rng_;
    steps_.clear();
    for (const auto& s : field("steps")) {
      SelectionLog l;
      l.views_before = s.at("views_before");
      l.selected = s.at("selected");
      l.candidates = s.at("candidates").get<std::vector<int>>();
      l.scores = s.at("scores").get<std::vector<double>>();
      l.prefiltered = s.at("prefiltered").get<std::vector<int>>();
      l.seconds = secondsFrom(s.at("seconds"));
      l.progress_psnr = s.at("progress_psnr");
      steps_.push_back(std::move(l));
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(checkpoint_, "steps", std::string("unexpected content: ") + e.what());
  }
  const std::string tag = field("tag");
  trainer_->loadCheckpoint(checkpoint_ + ".trainer." + tag);
  if (prefilter_) prefilter_->load(readFile(checkpoint_ + ".prefilter." + tag));
  return true;
}

std::optional<double> depthAuse(const Trainer& t, const std::vector<int>& train_views, const std::vector<int>& views,
                                double lambda) {
  const Scene& scene = t.scene();
  bool any = false;
  for (int v : views) any = any || scene.hasDepth(v);
  if (!any) return std::nullopt;
  const RasterSettings s = t.rasterSettings();
  Gaussians H = t.gaussians().zerosLike();
  for (int v : train_views) addViewInformation(t.gaussians(), scene.views[static_cast<std::size_t>(v)].camera, s, H);
  const Gaussians unc = withScalarColor(t.gaussians(), gaussianGeometryVariance(H, lambda));
  RasterSettings us = s;
  us.sh_degree = 0;
  us.background = {0, 0, 0};
  double sum = 0;
  int n = 0;
  for (int v : views) {
    if (!scene.hasDepth(v)) continue;
    const Camera& cam = scene.views[static_cast<std::size_t>(v)].camera;
    const ImageF gt = scene.depth(v);
    const RenderResult r = t.render(cam);
    const RenderResult u = rasterize(unc, cam, us);
    std::vector<double> err, un;
    for (std::size_t p = 0; p < gt.data.size(); ++p) {
      if (!(gt.data[p] > 0)) continue;
      err.push_back(std::abs(static_cast<double>(r.depth.data[p]) - gt.data[p]));
      un.push_back(u.rgb.data[3 * p]);
    }
    if (const auto c = sparsification(err, un)) {
      sum += c->ause;
      ++n;
    }
  }
  if (n == 0) return std::nullopt;
  return sum / n;
}

}  // namespace saresgs
