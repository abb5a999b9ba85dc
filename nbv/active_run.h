#pragma once
// The active reconstruction loop (DESIGN.md protocol): start from train index 0 plus 3
// views by farthest-point sampling; with k views train k x interval iterations, then
// select one more view among the remaining train views, until max_views; then train the
// rest of the iteration budget and evaluate. After each addition the model restarts from
// its initial state (an option continues instead). A checkpoint after every added view
// lets a killed run resume and end with the same numbers.
#include <nlohmann/json.hpp>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "geometry/lifting/sa_points.h"
#include "geometry/occupancy/coverage_score.h"
#include "geometry/scene/scene.h"
#include "nbv/selectors.h"
#include "splat/train/trainer.h"

namespace saresgs {

class OccupancyGrids;  // geometry/occupancy/occupancy_grid.h

enum class Method { kRandom, kFvs, kFisher, kCoverage, kSaHash, kSaResgs, kResgs };
Method parseMethod(const std::string& s);  // random|fvs|fisher|coverage|sa-hash|sa-resgs|resgs
const char* toString(Method m);

// What a method computes; everything else is left out.
struct MethodNeeds {
  bool fisher = false;    // renders and squared gradients of candidates
  bool coverage = false;  // SA-Points, occupancy grids, prefilter
  bool residual = false;  // residual supervision in training
};
MethodNeeds needsOf(Method m);

// Per-selection stage times, seconds.
struct SelectionSeconds {
  double lifting = 0, triangulation = 0, prefilter = 0, fisher = 0, training = 0;
  double exhaustive_fisher = 0;  // Fisher over all candidates, timed for comparison only
  // What choosing a view cost: every stage but training (and the comparison timing).
  double selection() const { return lifting + triangulation + prefilter + fisher; }
};
// The stage times as one JSON object (results.json and the checkpoint), and back; the
// reader throws nlohmann::json::exception when a stage is missing.
nlohmann::json toJson(const SelectionSeconds& s);
SelectionSeconds secondsFrom(const nlohmann::json& j);

// The prefilter of the coverage methods: builds its state from the scene, learns what the
// chosen views observe (SA-Points lifted against `render`: the trainer's renders in an
// active run, ground-truth renders in the coverage tool), and scores candidates (higher
// = more new coverage). Implemented in nbv/coverage_prefilter.cpp.
class CoveragePrefilter {
 public:
  virtual ~CoveragePrefilter() = default;
  // `depth` serves the `depth` lifting module (the renderer's own depth for the real view).
  virtual void observe(const std::vector<int>& new_views, const ViewRenderer& render, const DepthRenderer& depth,
                       SelectionSeconds& t) = 0;
  virtual std::vector<double> score(const std::vector<int>& candidates, SelectionSeconds& t) = 0;
  virtual const OccupancyGrids& grids() const = 0;
  virtual const LiftingReport& liftingReport() const = 0;  // summed over observed views
  // Serialised observed state, so a resumed run continues with the same grids.
  virtual std::string save() const = 0;
  virtual void load(const std::string& bytes) = 0;
};

struct PrefilterChoice {
  std::string set = "frustum";       // frustum | visible
  std::string encoding = "hash:13";  // hash:K (K = 11..19) | exact
  std::string score = "xor";         // xor | new
  double keep_fraction = 0.2;        // top N % kept for Fisher
  int visible_stride = 4;            // pixel stride of the visibility rays
  std::string lifting = "flow";      // flow (DIS + epipolar refinement) | depth (oracle)
  // Occupancy grid: resolution along the longest side and the SfM points per occupied
  // voxel. The paper's m = 5 (indoor) at 128 leaves a 12k-point SfM cloud almost empty,
  // so the default is sized for sparse clouds (see third_party_notes/openvdb.md).
  int resolution = 64;
  int min_points = 2;
  int upsample = 2;
};

// The coverage scoring options of an encoding ("hash:K", K in [min_bits, max_bits], or
// "exact") and a score ("xor" or "new"), with keep_fraction as the kept share; throws
// std::invalid_argument naming the value otherwise. The active loop takes the paper's
// 2^11..2^19; the sweep's tests go beyond.
PrefilterOptions prefilterOptions(const std::string& encoding, const std::string& score, double keep_fraction,
                                  int min_bits = 11, int max_bits = 19);

struct ActiveOptions {
  Method method = Method::kSaResgs;
  int initial_views = 4;
  int max_views = 20;
  int interval = 100;             // iterations per view held
  int total_iterations = 20000;
  bool reset_after_add = true;
  double fisher_lambda = 1e-6;
  ViewDistance fvs_metric = ViewDistance::kEuclidean;
  PrefilterChoice prefilter;
  bool time_exhaustive_fisher = false;  // prefiltered methods: also time Fisher on all
  int progress_test_views = 3;
  TrainerOptions trainer;
  std::uint64_t seed = 0;
};

// `paper`: interval 100, 20 000 iterations. `quick`: see active_run.cpp.
void applyPreset(const std::string& name, ActiveOptions& o);

struct SelectionLog {
  int views_before = 0;
  int selected = -1;
  std::vector<int> candidates;      // what the final scorer saw
  std::vector<double> scores;       // their scores
  std::vector<int> prefiltered;     // coverage methods: the kept top N %
  SelectionSeconds seconds;
  double progress_psnr = 0;         // on the progress test views, before selection
};

struct ActiveProgress {
  int views = 0, max_views = 0;
  int iteration = 0, total_iterations = 0;  // over the whole run
  double loss = 0, psnr = 0;                // latest loss; PSNR after the last phase
  std::size_t gaussians = 0;
};

struct ActiveResult {
  std::vector<int> initial_views, selected_views;
  std::vector<SelectionLog> steps;
  Evaluation test;
  std::optional<double> ause;
  SelectionSeconds total_seconds;
  int iterations = 0;  // training iterations over the whole run
  double seconds = 0;  // end to end, this process
};

class ActiveRun {
 public:
  // `checkpoint` names the checkpoint file (empty: none). A present checkpoint is resumed.
  ActiveRun(const Scene& scene, const ActiveOptions& opt, std::string checkpoint = {});
  ActiveResult run(const std::function<void(const ActiveProgress&)>& progress = {});
  const Trainer& trainer() const { return *trainer_; }

 private:
  int selectNext(SelectionLog& log);
  void saveCheckpoint() const;
  bool loadCheckpoint();

  Scene scene_;
  ActiveOptions opt_;
  std::string checkpoint_;
  std::unique_ptr<Trainer> trainer_;
  std::unique_ptr<CoveragePrefilter> prefilter_;
  std::mt19937_64 rng_;
  std::vector<int> initial_, selected_;
  std::vector<SelectionLog> steps_;
  int iterations_done_ = 0;
  int observed_upto_ = 0;  // selected_[0..observed_upto_) are in the prefilter's grids
};

// AUSE of the trainer's depth against ground truth on `views` (mean over views with
// depth), uncertainty rendered from the diagonal information of `train_views`; nullopt
// when no view has depth.
std::optional<double> depthAuse(const Trainer& t, const std::vector<int>& train_views, const std::vector<int>& views,
                                double lambda = 1e-6);

// Factory for the coverage prefilter (nbv/coverage_prefilter.cpp).
std::unique_ptr<CoveragePrefilter> makeCoveragePrefilter(const Scene& scene, const PrefilterChoice& o,
                                                         std::uint64_t seed);

}  // namespace saresgs
