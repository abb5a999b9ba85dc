#pragma once
// The 3DGS trainer that the active loop drives: train N iterations on a given set of
// views, render any camera, evaluate, reset to the initial state, checkpoint and resume
// bit-identically. Optionally adds SA-ResGS's residual supervision (residual.h).
//
// One iteration (as 3DGS, with the optional residual branch):
//   view <- next of a shuffled stack of the current views (refilled when empty)
//   active SH degree <- min(max, iteration / sh_interval); means lr <- log-linear decay
//   L = lambda_full L(render(G), I) + lambda_sub L(render(G_sub), I)   (residual)
//     or L(render(G), I)                                               (plain)
//   backward, densification statistics, Adam step, then densify / prune / reset
//   opacity on the schedule. (3DGS densifies before its optimiser step, which then skips
//   the replaced tensors; stepping first keeps every iteration's update.)
#include <array>
#include <cstdint>
#include <functional>
#include <random>
#include <span>
#include <string>
#include <stdexcept>
#include <string>
#include <vector>

#include "geometry/scene/scene.h"
#include "splat/gaussians.h"
#include "splat/loss.h"
#include "splat/rasterize.h"
#include "splat/train/adam.h"
#include "splat/train/densify.h"
#include "splat/train/residual.h"

namespace saresgs {

struct TrainerOptions {
  int max_sh_degree = 3;
  int sh_interval = 1000;          // iterations per SH degree step
  LearningRates lr;                // lr.means is multiplied by extent
  float means_lr_final = 1.6e-6f;  // times extent
  int means_lr_steps = 30000;
  DensifyOptions densify;
  ResidualOptions residual;
  RasterSettings raster;  // sh_degree is set by the schedule
  double lambda_ssim = 0.2;
  int random_init_points = 100000;  // used when the scene has no sparse points (3DGS's count)
  float initial_opacity = 0.1f;
  std::uint64_t seed = 0;
  // Divergence guard: every step checks its loss, and every this many iterations (and at
  // the end of train()) the model's arrays are checked for NaN or infinity (0: never).
  int finite_check_interval = 100;
};

// Thrown when training stops being finite: the iteration, the view, and what was found
// not finite ("loss", or a model array: "means", "log_scales", "rotations", "opacities",
// "sh"). Nothing after it should be written as a result.
class TrainingDiverged : public std::runtime_error {
 public:
  TrainingDiverged(int iteration, int view, const std::string& view_name, const std::string& what,
                   const std::string& detail)
      : std::runtime_error("training diverged at iteration " + std::to_string(iteration) + " (view " +
                           std::to_string(view) + ", " + view_name + "): " + what + " " + detail +
                           "; lower the learning rates (--schedule-scale, or the preset), or check the data"),
        iteration(iteration),
        view(view),
        what_(what) {}
  int iteration, view;
  const std::string& quantity() const { return what_; }

 private:
  std::string what_;
};

struct StageSeconds {
  double render = 0, loss = 0, backward = 0, optimizer = 0, densify = 0;
  double total() const { return render + loss + backward + optimizer + densify; }
};

struct TrainProgress {
  int iteration = 0;        // since the last reset
  int done = 0, total = 0;  // within this train() call
  double loss = 0;          // this iteration's loss
  double loss_ema = 0;      // 0.4 / 0.6 moving average, as 3DGS displays it
  std::size_t gaussians = 0;
};

struct ViewMetrics {
  int view = -1;
  double psnr = 0, ssim = 0;
};
struct Evaluation {
  std::vector<ViewMetrics> views;
  double psnr = 0, ssim = 0;  // means over views
  // The 8-bit renders, one per entry of views, when evaluate() was asked to keep them
  // (writeTestRenders then need not render again); empty otherwise.
  std::vector<Image8> renders;
};

// The number of Gaussians the trainer starts from (Trainer's constructor): one per sparse
// point, or random_init_points when the scene has none, capped by densify.max_gaussians.
std::size_t initialModelSize(const Scene& scene, const TrainerOptions& opt);

// What one training step renders and differentiates, kept from step to step so that a
// step allocates nothing once the model's and the images' sizes have been seen (the
// Trainer keeps one; any caller of viewLossAndGradient keeps its own).
struct StepBuffers {
  RenderResult render;  // the plain (or sub-only) branch
  RenderPair pair;      // residual supervision's two branches
  LossResult loss, loss_subset;
  ResidualSubset subset;  // residual supervision's G_sub
};

// The loss and its gradient for one view: the full render's loss, or with residual
// supervision lambda_full L(full) + lambda_sub L(G_sub) (sub-only: L(G_sub)). Gradients
// are added to `grad` and `grad_mean2d` (2 per Gaussian, pixels); the radii and
// visibility of the full render (of the subset in sub-only mode) come back for
// densification, as views into `buffers` (valid until its next use). Stage times are
// added to `seconds`.
struct ViewLoss {
  double loss = 0;
  std::span<const float> radii;
  std::span<const std::uint8_t> visible;
};
ViewLoss viewLossAndGradient(const Gaussians& g, const Camera& cam, const RasterSettings& s, const ImageF& target,
                             double lambda_ssim, const ResidualOptions& residual, std::mt19937_64& rng, Gaussians& grad,
                             std::vector<float>& grad_mean2d, StageSeconds& seconds, StepBuffers& buffers);

// 3DGS's position learning rate at `iteration`: log-linear from lr.means * extent to
// means_lr_final * extent over means_lr_steps iterations, then constant.
float meansLearningRate(const TrainerOptions& opt, int iteration, double extent);

class Trainer {
 public:
  // Builds the initial model from the scene's sparse points (or, when it has none,
  // random_init_points grey random points in the ball the train cameras look at:
  // viewFocus in geometry/camera/camera.h). The scene is copied (copies share its image cache).
  Trainer(const Scene& scene, const TrainerOptions& opt);

  // Trains `iterations` iterations on `views` (indices into scene.views); `progress` is
  // called after each iteration.
  void train(const std::vector<int>& views, int iterations,
             const std::function<void(const TrainProgress&)>& progress = {});
  // Declares that training will run until `iteration` even when it comes in several
  // train() calls (checkpoint chunks), so schedule decisions near the end (the opacity
  // reset guard) do not depend on the chunking. Cleared by reset().
  void planUntil(int iteration) { planned_until_ = iteration; }
  // One iteration on view `view`; returns its loss.
  double step(int view);
  // Throws TrainingDiverged naming the first model array that holds NaN or infinity.
  void checkFinite(int view) const;

  RenderResult render(const Camera& cam) const;
  // PSNR and SSIM of each view against its image; without `with_ssim` PSNR only (ssim 0),
  // for evaluations over many views (an active run's whole path).
  Evaluation evaluate(const std::vector<int>& views, bool keep_renders = false, bool with_ssim = true) const;
  // The model, optimiser and schedules as after construction; the random generator
  // continues (so that repeated resets do not replay the same views).
  void reset();
  // Puts the SH schedule on an outer clock that stood at `start` when this model (re)started
  // at degree 0: the degree rises each time start + iteration() crosses a multiple of
  // sh_interval, as in FisherRF's reference, which keeps one global iteration counter
  // across the model resets of its active loop. reset() returns to the plain schedule
  // (start 0).
  void setShClockStart(int start) { sh_clock_start_ = start; }

  // Everything a resumed run needs, written atomically; load throws InputError naming
  // the file and field on a mismatch (another scene size, truncated file).
  void saveCheckpoint(const std::string& path) const;
  void loadCheckpoint(const std::string& path);

  const Gaussians& gaussians() const { return g_; }
  // For tests and importers; when the count changes, Adam and the statistics restart.
  Gaussians& mutableGaussians() { return g_; }
  const Scene& scene() const { return scene_; }
  const TrainerOptions& options() const { return opt_; }
  int iteration() const { return iteration_; }
  int activeShDegree() const;
  RasterSettings rasterSettings() const;
  const StageSeconds& seconds() const { return seconds_; }
  const DensifyReport& lastDensify() const { return last_densify_; }

 private:
  const ImageF& target(int view);
  // Scene::random_background: draws this step's colour into s.background and returns the
  // view's image with that colour behind it.
  const ImageF& randomBackgroundTarget(int view, RasterSettings& s);
  int nextView(const std::vector<int>& views);

  Scene scene_;
  TrainerOptions opt_;
  int sh_clock_start_ = 0;
  Gaussians initial_, g_, grad_;
  bool grad_cleared_ = false;  // grad_ is all zeros (the last step's Adam cleared it)
  std::vector<float> grad2d_;
  AdamState adam_;
  DensifyStats stats_;
  DensifyReport last_densify_;
  std::mt19937_64 rng_;
  int iteration_ = 0;
  int plan_end_ = 0;       // iteration at which the current training plan ends
  int planned_until_ = 0;  // planUntil()'s value; 0: none
  double loss_ema_ = 0;
  std::vector<int> view_set_, view_stack_;
  // The current step's view as float, converted from the scene's 8-bit image into one
  // reused buffer: a float copy per view (12 bytes a pixel, 309 MB for room360's 131 views
  // at 512x384) cost more in first-touch page faults than the conversion costs per step.
  ImageF target_;
  int target_view_ = -1;
  ImageF random_target_;  // randomBackgroundTarget's image
  StageSeconds seconds_;
  StepBuffers step_buffers_;  // a step's renders and loss images, reused
};

}  // namespace saresgs
