#include "nbv/active_run.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "geometry/error.h"
#include "geometry/io/atomic_file.h"
#include "geometry/io/json_file.h"
#include "geometry/scene/cameras_json.h"
#include "nbv/ause.h"
#include "nbv/initial_views.h"
#include "nbv/selection_seconds.h"
#include "nbv/step_report.h"
#include "nbv/selection_step.h"

namespace saresgs {

namespace {

// Version 2 stores the steps as the run report does (views by name).
constexpr const char* kCheckpointFormat = "saresgs-active-checkpoint-2";

using Clock = std::chrono::steady_clock;

}  // namespace

ActiveRun::ActiveRun(const Scene& scene, const ActiveOptions& opt, std::string checkpoint)
    : scene_(scene), opt_(opt), checkpoint_(std::move(checkpoint)), rng_(opt.seed) {
  if (scene_.train.empty()) throw std::invalid_argument("ActiveRun: the scene has no train views");
  if (opt_.initial_views < 1 || opt_.max_views < opt_.initial_views)
    throw std::invalid_argument("ActiveRun: need 1 <= initial views <= max views");
  const MethodNeeds needs = needsOf(opt_.method);
  TrainerOptions to = opt_.trainer;
  to.seed = opt_.seed;
  to.residual.enabled = needs.residual;
  if (!opt_.replay.empty()) checkReplay();
  if (opt_.method == Method::kCustom && !opt_.custom_selector && opt_.replay.empty())
    throw std::invalid_argument(
        "method custom: a selector function written by the caller (the Python module's "
        "saresgs.ActiveRun(dataset, selector=f)); the command line has none");
  trainer_ = std::make_unique<Trainer>(scene_, to);
  // A replay selects nothing, so it needs no prefilter.
  if (needs.coverage && opt_.replay.empty()) prefilter_ = makeCoveragePrefilter(scene_, opt_.prefilter);
  if (needs.surface && opt_.replay.empty() && opt_.hybrid_coverage != HybridCoverage::kViewDistance)
    surface_ = std::make_unique<SurfaceCoverage>(scene_, opt_.hybrid_surface);
}

// The replayed sequence must be one this run could have held: distinct train views, at
// least the initial ones and as many as the run will hold.
void ActiveRun::checkReplay() const {
  const std::vector<int>& r = opt_.replay;
  const int n_initial = std::min<int>(opt_.initial_views, static_cast<int>(scene_.train.size()));
  const int held = std::min<int>(std::max(opt_.max_views, n_initial), static_cast<int>(scene_.train.size()));
  if (static_cast<int>(r.size()) < held)
    throw std::invalid_argument("replay: the replayed sequence holds " + std::to_string(r.size()) +
                                " views, this run holds " + std::to_string(held) + " (--max-views " +
                                std::to_string(opt_.max_views) + ")");
  for (std::size_t i = 0; i < r.size(); ++i) {
    if (std::find(scene_.train.begin(), scene_.train.end(), r[i]) == scene_.train.end())
      throw std::invalid_argument("replay: view index " + std::to_string(r[i]) +
                                  " is not a train view of this dataset");
    if (std::find(r.begin(), r.begin() + static_cast<long>(i), r[i]) != r.begin() + static_cast<long>(i))
      throw std::invalid_argument("replay: view index " + std::to_string(r[i]) + " appears twice");
  }
}

void ActiveRun::report(ActivePhase phase, int done, int total) {
  last_.phase = phase;
  last_.phase_done = done;
  last_.phase_total = total;
  last_.gaussians = trainer_->gaussians().size();
  if (progress_) progress_(last_);
}

int ActiveRun::selectNext(SelectionLog& log) {
  std::vector<int> candidates;
  for (int v : scene_.train)
    if (std::find(selected_.begin(), selected_.end(), v) == selected_.end()) candidates.push_back(v);
  log.views_before = static_cast<int>(selected_.size());
  if (!opt_.replay.empty()) {
    // Fixed order: the next view of the replayed sequence (checkReplay made it a candidate).
    const int next = opt_.replay.at(selected_.size());
    log.candidates = {next};
    return next;
  }
  // The SA-Point prefilter holds the run's state (what the held views observed), so its
  // scores and cut are made here; everything else is the method's (nbv/selection_step.h).
  const MethodNeeds needs = needsOf(opt_.method);
  std::vector<int> pool = candidates;
  std::vector<double> coverage;
  if (needs.coverage) {
    const std::vector<int> fresh(selected_.begin() + observed_upto_, selected_.end());
    for (std::size_t i = 0; i < fresh.size(); ++i) {
      // One view at a time, so that progress is reported per lifted view.
      report(ActivePhase::kLifting, static_cast<int>(i), static_cast<int>(fresh.size()));
      prefilter_->observe(
          {fresh[i]}, [this](const Camera& c) { return trainer_->render(c).rgb; },
          [this](const Camera& c) { return trainer_->render(c).depth; }, log.seconds);
    }
    observed_upto_ = static_cast<int>(selected_.size());
    report(ActivePhase::kPrefilter, 0, static_cast<int>(candidates.size()));
    coverage = prefilter_->score(candidates, log.seconds);
    if (needs.fisher) {
      const auto t0 = Clock::now();
      pool = topFraction(coverage, candidates, opt_.prefilter.keep_fraction);
      log.seconds.prefilter += secondsSince(t0);
      log.prefiltered = pool;
    }
  }
  SelectionStep step{scene_,         *trainer_,
                     opt_,           selected_,
                     candidates,     std::move(pool),
                     coverage,       rng_,
                     surface_.get(), [this](ActivePhase p, int done, int total) { report(p, done, total); }};
  return selectorOf(opt_.method)(step, log);
}

void ActiveRun::begin() {
  if (begun_) return;
  begun_ = true;
  start_ = Clock::now();
  last_ = {};
  last_.max_views = opt_.max_views;
  if (!loadCheckpoint()) {
    std::vector<Eigen::Vector3d> centers;
    for (int v : scene_.train) centers.push_back(scene_.views[static_cast<std::size_t>(v)].camera.center());
    for (int i : farthestPointSampling(centers, opt_.initial_views, 0))
      initial_.push_back(scene_.train[static_cast<std::size_t>(i)]);
    if (!opt_.replay.empty())
      initial_.assign(opt_.replay.begin(), opt_.replay.begin() + static_cast<long>(initial_.size()));
    selected_ = initial_;
  }
  progress_views_.clear();
  for (std::size_t i = 0; i < scene_.test.size() && static_cast<int>(i) < opt_.progress_test_views; ++i)
    progress_views_.push_back(
        scene_.test[i * scene_.test.size() / std::min<std::size_t>(scene_.test.size(), opt_.progress_test_views)]);
  last_psnr_ = 0;
}

bool ActiveRun::lastPhase() const {
  const int k = static_cast<int>(selected_.size());
  return k >= opt_.max_views || k >= static_cast<int>(scene_.train.size());
}

void ActiveRun::trainPhase() {
  begin();
  if (phase_trained_) return;
  const int k = static_cast<int>(selected_.size());
  const bool last = lastPhase();
  const int phase = last ? std::max(opt_.total_iterations - iterations_done_, k * opt_.interval) : k * opt_.interval;
  if (opt_.reset_after_add) {
    trainer_->reset();
    if (opt_.global_sh_clock) trainer_->setShClockStart(iterations_done_);
  }
  const auto t0 = Clock::now();
  last_.views = k;
  last_.total_iterations = std::max(opt_.total_iterations, iterations_done_ + phase);
  last_.psnr = last_psnr_;
  trainer_->train(selected_, phase, [&](const TrainProgress& p) {
    last_.iteration = iterations_done_ + p.done;
    last_.loss = p.loss_ema;
    report(ActivePhase::kTraining, p.done, phase);
  });
  phase_seconds_ = secondsSince(t0);
  iterations_done_ += phase;
  phase_trained_ = true;
  if (!progress_views_.empty()) last_psnr_ = trainer_->evaluate(progress_views_).psnr;
  if (last) {
    // The final phase's training belongs to no selection; a log entry without a
    // selected view keeps it in the totals.
    SelectionLog tail;
    tail.views_before = k;
    tail.seconds.training = phase_seconds_;
    tail.progress_psnr = last_psnr_;
    steps_.push_back(std::move(tail));
    finished_ = true;
  }
}

int ActiveRun::nextView(SelectionLog* out) {
  trainPhase();
  if (finished_)
    throw std::logic_error("nextView: the run holds its last view (" + std::to_string(selected_.size()) + ")");
  if (!pending_) {
    SelectionLog log;
    log.seconds.training = phase_seconds_;
    log.progress_psnr = last_psnr_;
    log.selected = selectNext(log);
    pending_ = std::move(log);
  }
  if (out) *out = *pending_;
  return pending_->selected;
}

void ActiveRun::addView(int v) {
  trainPhase();
  if (finished_)
    throw std::logic_error("addView: the run holds its last view (" + std::to_string(selected_.size()) + ")");
  if (std::find(scene_.train.begin(), scene_.train.end(), v) == scene_.train.end())
    throw std::invalid_argument("addView: view " + std::to_string(v) + " is not a train view");
  if (std::find(selected_.begin(), selected_.end(), v) != selected_.end())
    throw std::invalid_argument("addView: view " + std::to_string(v) + " is held already");
  SelectionLog log;
  if (pending_) {
    log = std::move(*pending_);  // the method's record, whichever view is added
  } else {
    log.views_before = static_cast<int>(selected_.size());
    log.seconds.training = phase_seconds_;
    log.progress_psnr = last_psnr_;
  }
  pending_.reset();
  log.selected = v;
  selected_.push_back(v);
  steps_.push_back(std::move(log));
  phase_trained_ = false;
  saveCheckpoint();
}

ActiveResult ActiveRun::run(const std::function<void(const ActiveProgress&)>& progress) {
  progress_ = progress;
  begin();
  while (true) {
    trainPhase();
    if (finished_) break;
    addView(nextView());
  }
  ActiveResult r = finish();
  progress_ = {};
  return r;
}

ActiveResult ActiveRun::finish() {
  begin();
  if (!finished_ && lastPhase()) trainPhase();
  if (!finished_)
    throw std::logic_error("finish: the run holds " + std::to_string(selected_.size()) + " of " +
                           std::to_string(opt_.max_views) + " views; add views first (or call run())");
  ActiveResult r;
  r.initial_views = initial_;
  r.selected_views = selected_;
  r.steps = steps_;
  for (const auto& s : steps_) r.total_seconds += s.seconds;
  r.iterations = iterations_done_;
  if (prefilter_) r.prefilter = prefilter_->regime();
  // The phases before the last trained k x interval for k views held (checkLoadedState
  // holds a resumed run to that); the last trained the rest.
  int before_last = 0;
  for (std::size_t k = initial_.size(); k < selected_.size(); ++k) {
    r.phase_iterations.push_back(static_cast<int>(k) * opt_.interval);
    before_last += r.phase_iterations.back();
  }
  r.phase_iterations.push_back(iterations_done_ - before_last);
  report(ActivePhase::kFinalEvaluation, 0, 1);
  r.test = trainer_->evaluate(scene_.test.empty() ? scene_.train : scene_.test);
  r.ause = depthAuse(*trainer_, selected_, scene_.test.empty() ? scene_.train : scene_.test, opt_.fisher_lambda);
  report(ActivePhase::kFinalEvaluation, 1, 1);
  if (opt_.final_iterations > 0) {
    // The method's own training first, then (for methods that train otherwise than plain
    // 3DGS) the plain refit of the same views.
    last_.views = static_cast<int>(selected_.size());
    auto fit = [&](bool method_training, ActivePhase phase) {
      const TrainerOptions to = finalFitOptions(opt_, method_training);
      auto t = std::make_unique<Trainer>(scene_, to);
      t->train(selected_, opt_.final_iterations, [&](const TrainProgress& p) {
        last_.loss = p.loss_ema;
        report(phase, p.done, opt_.final_iterations);
      });
      FinalFit f{opt_.final_iterations,
                 to.residual.enabled,
                 t->evaluate(scene_.test.empty() ? scene_.train : scene_.test),
                 {}};
      std::vector<int> every(scene_.views.size());
      for (std::size_t i = 0; i < every.size(); ++i) every[i] = static_cast<int>(i);
      f.path = t->evaluate(every, /*keep_renders=*/false, /*with_ssim=*/false).views;
      return std::make_pair(std::move(t), f);
    };
    auto [model, f] = fit(true, ActivePhase::kFinalFit);
    final_fit_ = std::move(model);
    r.final_fit = f;
    if (f.residual && opt_.plain_refit) {
      auto [plain, g] = fit(false, ActivePhase::kFinalFitViews);
      final_fit_views_ = std::move(plain);
      r.final_fit_views = g;
    } else if (!f.residual) {
      r.final_fit_views = f;
    }
  }
  r.seconds = secondsSince(start_);
  return r;
}

void ActiveRun::saveCheckpoint() const {
  if (checkpoint_.empty()) return;
  const std::string tag = std::to_string(selected_.size());
  trainer_->saveCheckpoint(checkpoint_ + ".trainer." + tag);
  if (prefilter_) writeFileAtomic(checkpoint_ + ".prefilter." + tag, prefilter_->save());
  nlohmann::json j;
  j["format"] = kCheckpointFormat;
  j["method"] = toString(opt_.method);
  j["seed"] = opt_.seed;
  j["views"] = scene_.views.size();
  // The colour and kind only: where it came from may be said another way on resume.
  j["background"] = backgroundJson(scene_);
  j["background"].erase("from");
  j["initial"] = initial_;
  j["selected"] = selected_;
  j["iterations_done"] = iterations_done_;
  j["observed_upto"] = observed_upto_;
  std::ostringstream rs;
  rs << rng_;
  j["rng"] = rs.str();
  j["tag"] = tag;
  j["steps"] = nlohmann::json::array();
  for (const SelectionLog& s : steps_) j["steps"].push_back(toJson(stepReport(scene_, s)));
  writeFileAtomic(checkpoint_, j.dump() + "\n");
  // Older companions are obsolete once the state that names the new ones is in place.
  const int previous = static_cast<int>(selected_.size()) - 1;
  std::error_code ec;
  std::filesystem::remove(checkpoint_ + ".trainer." + std::to_string(previous), ec);
  std::filesystem::remove(checkpoint_ + ".prefilter." + std::to_string(previous), ec);
}

// Every field read from a checkpoint is checked against the run it belongs to, so that a
// corrupt or foreign file cannot index out of range or plan a runaway phase.
void ActiveRun::checkLoadedState() const {
  const int n_initial = std::min<int>(opt_.initial_views, static_cast<int>(scene_.train.size()));
  if (static_cast<int>(initial_.size()) != n_initial)
    throw InputError(checkpoint_, "initial", "expected " + std::to_string(n_initial) + " initial views");
  if (selected_.size() < initial_.size() || !std::equal(initial_.begin(), initial_.end(), selected_.begin()))
    throw InputError(checkpoint_, "selected", "does not start with the initial views");
  if (static_cast<int>(selected_.size()) > std::max(opt_.max_views, n_initial))
    throw InputError(checkpoint_, "selected", "holds more views than --max-views " + std::to_string(opt_.max_views));
  std::vector<int> seen;
  for (int v : selected_) {
    if (std::find(scene_.train.begin(), scene_.train.end(), v) == scene_.train.end())
      throw InputError(checkpoint_, "selected", std::to_string(v) + " is not a train view of this dataset");
    if (std::find(seen.begin(), seen.end(), v) != seen.end())
      throw InputError(checkpoint_, "selected", std::to_string(v) + " appears twice");
    seen.push_back(v);
  }
  // The phases so far trained k x interval iterations for k = initial .. held - 1.
  long long expected = 0;
  for (std::size_t k = initial_.size(); k < selected_.size(); ++k)
    expected += static_cast<long long>(k) * opt_.interval;
  if (iterations_done_ != expected)
    throw InputError(checkpoint_, "iterations_done",
                     std::to_string(iterations_done_) + ", expected " + std::to_string(expected) +
                         " for these views at --interval " + std::to_string(opt_.interval));
  if (observed_upto_ < 0 || observed_upto_ > static_cast<int>(selected_.size()))
    throw InputError(checkpoint_, "observed_upto", "outside 0.." + std::to_string(selected_.size()));
}

bool ActiveRun::loadCheckpoint() {
  if (checkpoint_.empty() || !std::filesystem::exists(checkpoint_)) return false;
  const std::string& f = checkpoint_;
  const nlohmann::json j = readJsonFile(f);
  jsonObject(j, f, "json");
  auto field = [&](const char* name) -> const nlohmann::json& { return jsonMember(j, name, f, ""); };
  auto text = [&](const char* name) { return jsonString(field(name), f, name); };
  if (text("format") != kCheckpointFormat) throw InputError(f, "format", "not an active-run checkpoint");
  if (text("method") != toString(opt_.method))
    throw InputError(f, "method", "written by method " + j["method"].dump() + ", this run is " + toString(opt_.method));
  constexpr long long kMaxCount = 2'000'000'000;
  if (static_cast<std::uint64_t>(jsonInteger(field("seed"), f, "seed", 0, std::numeric_limits<long long>::max())) !=
      opt_.seed)
    throw InputError(f, "seed", "written with seed " + j["seed"].dump());
  if (jsonInteger(field("views"), f, "views", 0, kMaxCount) != static_cast<long long>(scene_.views.size()))
    throw InputError(f, "views", "written for another scene");
  if (j.contains("background")) {
    nlohmann::json mine = backgroundJson(scene_);
    mine.erase("from");
    if (j["background"] != mine)
      throw InputError(f, "background",
                       "written with background " + j["background"].dump() + ", this run's is " + mine.dump() +
                           ": resume with the same --background");
  }
  // View indices are read in range of this scene's views; checkLoadedState checks the rest.
  const long long last_view = static_cast<long long>(scene_.views.size()) - 1;
  auto views = [&](const char* name) {
    std::vector<int> v;
    for (long long x : jsonIntegers(field(name), f, name, 0, last_view)) v.push_back(static_cast<int>(x));
    return v;
  };
  initial_ = views("initial");
  selected_ = views("selected");
  iterations_done_ = static_cast<int>(jsonInteger(field("iterations_done"), f, "iterations_done", 0, kMaxCount));
  observed_upto_ = static_cast<int>(jsonInteger(field("observed_upto"), f, "observed_upto", 0, kMaxCount));
  std::istringstream rs(text("rng"));
  rs >> rng_;
  if (rs.fail()) throw InputError(f, "rng", "expected the state of a 64-bit Mersenne Twister");
  checkLoadedState();
  steps_.clear();
  const nlohmann::json& steps = jsonArray(field("steps"), f, "steps", selected_.size());
  for (std::size_t i = 0; i < steps.size(); ++i)
    steps_.push_back(selectionLog(scene_, stepReportFromJson(steps[i], f, jsonPath("steps", i)), f));
  if (steps_.size() != selected_.size() - initial_.size())
    throw InputError(f, "steps",
                     std::to_string(steps_.size()) + " steps for " +
                         std::to_string(selected_.size() - initial_.size()) + " added views");
  const std::string tag = text("tag");
  if (tag != std::to_string(selected_.size()))
    throw InputError(f, "tag", "expected \"" + std::to_string(selected_.size()) + "\", the number of views held");
  trainer_->loadCheckpoint(checkpoint_ + ".trainer." + tag);
  if (prefilter_) prefilter_->load(readFile(checkpoint_ + ".prefilter." + tag), checkpoint_ + ".prefilter." + tag);
  return true;
}

}  // namespace saresgs
