#include "splat/train/trainer.h"

#include <algorithm>
#include <optional>
#include <utility>
#include <chrono>
#include <cmath>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>

#include "geometry/error.h"
#include "geometry/float_env.h"
#include "geometry/io/atomic_file.h"
#include "splat/loss.h"
#include "splat/metrics.h"
#include "splat/train/init.h"

namespace saresgs {

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace

std::size_t initialModelSize(const Scene& scene, const TrainerOptions& opt) {
  if (!scene.points.empty()) return scene.points.size();
  // A model cap bounds the initial random model too.
  const auto n = static_cast<std::size_t>(opt.random_init_points);
  return opt.densify.max_gaussians > 0 ? std::min(n, opt.densify.max_gaussians) : n;
}

namespace {

Gaussians initialModel(const Scene& scene, const TrainerOptions& opt) {
  std::vector<ColoredPoint> pts;
  if (!scene.points.empty()) {
    pts.reserve(scene.points.size());
    for (const auto& p : scene.points)
      pts.push_back({p.xyz, {p.rgb[0] / 255.0f, p.rgb[1] / 255.0f, p.rgb[2] / 255.0f}});
  } else {
    // No points: grey random points in the ball the cameras see (viewFocus: about the
    // point nearest their optical axes, the radius a view-filling object's). On
    // NeRF-synthetic (cameras 4 from the origin, 40 deg field of view) that is the sphere
    // in 3DGS's own [-1.3, 1.3]^3; the mean of the camera centres, which an upper
    // hemisphere puts well above the objects, is not used.
    const ViewFocus focus = viewFocus(scene.cameras(scene.train));
    std::mt19937_64 init_rng(opt.seed ^ 0x5eed1417ULL);
    pts = randomPointsInBall(focus.center, std::max(focus.radius, 1e-6), static_cast<int>(initialModelSize(scene, opt)),
                             init_rng);
  }
  return gaussiansFromPoints(pts, opt.max_sh_degree, opt.initial_opacity);
}

void scaleImage(ImageF& img, float w) {
  if (w == 1.0f) return;
  for (float& x : img.data) x *= w;
}

// --- checkpoint serialisation: a tagged binary stream -----------------------------
constexpr char kMagic[8] = {'S', 'A', 'R', 'C', 'K', 'P', 'T', '1'};

struct Writer {
  std::ostream& os;
  template <typename T>
  void pod(const T& v) {
    os.write(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  template <typename T>
  void vec(const std::vector<T>& v) {
    pod<std::uint64_t>(v.size());
    os.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(T)));
  }
  void model(const Gaussians& g) {
    pod<std::int32_t>(g.max_sh_degree);
    g.forEachArray([&](const std::vector<float>& a, std::size_t) { vec(a); });
  }
};

struct Reader {
  const std::string& bytes;
  const std::string& file;
  std::size_t pos = 0;
  void need(std::size_t n, const char* field) {
    if (bytes.size() - pos < n) throw InputError(file, field, "file is truncated");
  }
  template <typename T>
  T pod(const char* field) {
    need(sizeof(T), field);
    T v;
    std::memcpy(&v, bytes.data() + pos, sizeof(T));
    pos += sizeof(T);
    return v;
  }
  template <typename T>
  std::vector<T> vec(const char* field, std::size_t expected = SIZE_MAX) {
    const auto n = pod<std::uint64_t>(field);
    if (expected != SIZE_MAX && n != expected)
      throw InputError(file, field, "expected " + std::to_string(expected) + " values, found " + std::to_string(n));
    if (n > (bytes.size() - pos) / sizeof(T)) throw InputError(file, field, "file is truncated");
    std::vector<T> v(n);
    // An empty vector's data() may be null, which memcpy must never be given.
    if (n) std::memcpy(v.data(), bytes.data() + pos, n * sizeof(T));
    pos += n * sizeof(T);
    return v;
  }
  Gaussians model(const char* field) {
    Gaussians g;
    g.max_sh_degree = pod<std::int32_t>(field);
    if (g.max_sh_degree < 0 || g.max_sh_degree > 3) throw InputError(file, field, "SH degree outside 0..3");
    std::size_t n = SIZE_MAX;
    g.forEachArray([&](std::vector<float>& a, std::size_t per) {
      a = vec<float>(field, n == SIZE_MAX ? SIZE_MAX : n * per);
      if (n == SIZE_MAX) {
        if (a.size() % per) throw InputError(file, field, "array length is not a multiple of " + std::to_string(per));
        n = a.size() / per;
      }
    });
    return g;
  }
};

// The first model array holding NaN or infinity ("means", "log_scales", "rotations",
// "opacities", "sh", in forEachArray's order) and the Gaussian it belongs to.
std::optional<std::pair<const char*, std::size_t>> firstNonFinite(const Gaussians& g) {
  static constexpr const char* kNames[] = {"means", "log_scales", "rotations", "opacities", "sh"};
  std::optional<std::pair<const char*, std::size_t>> found;
  int k = 0;
  g.forEachArray([&](const std::vector<float>& a, std::size_t per) {
    for (std::size_t i = 0; i < a.size() && !found; ++i)
      if (!std::isfinite(a[i])) found = std::pair{kNames[k], i / per};
    ++k;
  });
  return found;
}

}  // namespace

ViewLoss viewLossAndGradient(const Gaussians& g, const Camera& cam, const RasterSettings& settings,
                             const ImageF& target, double lambda_ssim, const ResidualOptions& res, std::mt19937_64& rng,
                             Gaussians& grad, std::vector<float>& grad_mean2d, StageSeconds& seconds,
                             StepBuffers& buffers) {
  // A step reads the renders' colours (and the state their backward keeps), never their
  // depth or contributor counts: the kernels skip them.
  RasterSettings s = settings;
  s.depth_and_contributors = false;
  ViewLoss out;
  // One branch: render (optionally a subset), loss, backward scaled by `weight`.
  auto branch = [&](std::span<const std::uint8_t> mask, double weight) {
    auto t0 = Clock::now();
    RenderResult& fwd = buffers.render;
    rasterize(g, cam, s, mask, fwd);
    seconds.render += since(t0);
    t0 = Clock::now();
    LossResult& L = buffers.loss;
    photometricLoss(fwd.rgb, target, lambda_ssim, true, L);
    scaleImage(L.grad, static_cast<float>(weight));
    seconds.loss += since(t0);
    t0 = Clock::now();
    rasterizeBackward(g, cam, s, fwd, L.grad, grad, &grad_mean2d);
    seconds.backward += since(t0);
    out.loss += weight * L.loss;
    out.radii = fwd.radii;
    out.visible = fwd.visible;
  };
  if (!res.enabled) {
    branch({}, 1.0);
  } else if (res.sub_only) {
    ResidualSubset& sub = buffers.subset;
    selectResidualSubset(g, res, rng, sub);
    branch(sub.mask, 1.0);
  } else {
    // Both branches from one projection, sort and tile walk, forward and backward
    // (rasterizeWithSubset): the same renders and losses as the full branch followed by
    // the subset branch, and the same gradients up to float rounding (the branches'
    // projected gradients are summed before the chain rule). Drawing the subset first
    // draws the same numbers, as the full branch uses no randomness.
    ResidualSubset& sub = buffers.subset;
    selectResidualSubset(g, res, rng, sub);
    auto t0 = Clock::now();
    RenderPair& fwd = buffers.pair;
    rasterizeWithSubset(g, cam, s, sub.mask, fwd);
    seconds.render += since(t0);
    t0 = Clock::now();
    // The two images' losses side by side: each is deterministic for any thread count,
    // and on a small image one loss alone keeps two cores only partly busy. Each runs
    // isolated, so that a thread waiting inside one loss does not start the other there:
    // the nested call would find the loss's per-thread scratch busy and allocate its own
    // (splat/kept_buffers.h).
    LossResult& Lf = buffers.loss;
    LossResult& Ls = buffers.loss_subset;
    tbb::parallel_invoke(
        [&] {
          tbb::this_task_arena::isolate([&] {
            const FloatEnvGuard fenv;  // geometry/float_env.h: this may run on a worker
            photometricLoss(fwd.full.rgb, target, lambda_ssim, true, Lf);
            scaleImage(Lf.grad, static_cast<float>(res.lambda_full));
          });
        },
        [&] {
          tbb::this_task_arena::isolate([&] {
            const FloatEnvGuard fenv;
            photometricLoss(fwd.subset.rgb, target, lambda_ssim, true, Ls);
            scaleImage(Ls.grad, static_cast<float>(res.lambda_sub));
          });
        });
    seconds.loss += since(t0);
    t0 = Clock::now();
    rasterizeBackwardWithSubset(g, cam, s, fwd, Lf.grad, Ls.grad, grad, &grad_mean2d);
    seconds.backward += since(t0);
    out.loss += res.lambda_full * Lf.loss;
    out.loss += res.lambda_sub * Ls.loss;
    out.radii = fwd.full.radii;
    out.visible = fwd.full.visible;
  }
  return out;
}

float meansLearningRate(const TrainerOptions& opt, int iteration, double extent) {
  const double t = std::clamp(static_cast<double>(iteration) / std::max(1, opt.means_lr_steps), 0.0, 1.0);
  return static_cast<float>(
      std::exp(std::log(opt.lr.means * extent) * (1 - t) + std::log(opt.means_lr_final * extent) * t));
}

Trainer::Trainer(const Scene& scene, const TrainerOptions& opt) : scene_(scene), opt_(opt), rng_(opt.seed) {
  if (scene_.views.empty()) throw std::invalid_argument("Trainer: the scene has no views");
  initial_ = initialModel(scene_, opt_);
  reset();
}

void Trainer::reset() {
  g_ = initial_;
  adam_.resetFor(g_);
  stats_.resize(g_.size());
  iteration_ = 0;
  loss_ema_ = 0;
  planned_until_ = 0;
  view_stack_.clear();
  sh_clock_start_ = 0;
}

int Trainer::activeShDegree() const {
  // Multiples of sh_interval in (start, start + iteration]: the plain schedule for start 0.
  const int steps = opt_.sh_interval > 0
                        ? (sh_clock_start_ + iteration_) / opt_.sh_interval - sh_clock_start_ / opt_.sh_interval
                        : opt_.max_sh_degree;
  return std::min(opt_.max_sh_degree, steps);
}

RasterSettings Trainer::rasterSettings() const {
  RasterSettings s = opt_.raster;
  s.sh_degree = activeShDegree();
  if (scene_.background) s.background = *scene_.background;
  return s;
}

const ImageF& Trainer::target(int view) {
  if (view != target_view_) {
    target_view_ = -1;  // stays unset if the image cannot be read
    toFloatInto(scene_.image(view), target_);
    target_view_ = view;
  }
  return target_;
}

const ImageF& Trainer::randomBackgroundTarget(int view, RasterSettings& s) {
  // A fresh colour for this step, rendered behind the model and put behind the image:
  // the image was composited on scene.load.background, so where alpha is a the target is
  // image + (1 - a) (colour - load.background). An opaque image stays as it is.
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (float& c : s.background) c = unit(rng_);
  const ImageF& composited = target(view);
  const Image8* alpha = scene_.alpha(view);
  random_target_ = composited;
  if (alpha) {
    float shift[3];
    for (int c = 0; c < 3; ++c)
      shift[c] = s.background[static_cast<std::size_t>(c)] - scene_.load.background[static_cast<std::size_t>(c)];
    for (std::size_t p = 0; p < alpha->data.size(); ++p) {
      const float clear = 1.0f - alpha->data[p] * (1.0f / 255.0f);
      for (int c = 0; c < 3; ++c) random_target_.data[3 * p + static_cast<std::size_t>(c)] += clear * shift[c];
    }
  }
  return random_target_;
}

int Trainer::nextView(const std::vector<int>& views) {
  if (views != view_set_) {
    view_set_ = views;
    view_stack_.clear();
  }
  if (view_stack_.empty()) {
    view_stack_ = views;
    std::shuffle(view_stack_.begin(), view_stack_.end(), rng_);
  }
  const int v = view_stack_.back();
  view_stack_.pop_back();
  return v;
}

void Trainer::train(const std::vector<int>& views, int iterations,
                    const std::function<void(const TrainProgress&)>& progress) {
  if (views.empty()) throw std::invalid_argument("Trainer::train: no views to train on");
  for (int v : views)
    if (v < 0 || v >= static_cast<int>(scene_.views.size()))
      throw std::invalid_argument("Trainer::train: view index " + std::to_string(v) + " is not in the scene");
  plan_end_ = std::max(planned_until_, iteration_ + iterations);
  int view = -1;
  for (int k = 0; k < iterations; ++k) {
    view = nextView(views);
    const double loss = step(view);
    loss_ema_ = iteration_ == 1 ? loss : 0.4 * loss + 0.6 * loss_ema_;
    if (progress) progress({iteration_, k + 1, iterations, loss, loss_ema_, g_.size()});
  }
  if (opt_.finite_check_interval > 0 && view >= 0) checkFinite(view);
  plan_end_ = 0;
}

void Trainer::checkFinite(int view) const {
  if (const auto bad = firstNonFinite(g_))
    throw TrainingDiverged(iteration_, view, scene_.views.at(static_cast<std::size_t>(view)).name, bad->first,
                           "of Gaussian " + std::to_string(bad->second) + " is not finite");
}

double Trainer::step(int view) {
  ++iteration_;
  const Camera& cam = scene_.views.at(static_cast<std::size_t>(view)).camera;
  RasterSettings s = rasterSettings();
  const ImageF& gt = scene_.random_background ? randomBackgroundTarget(view, s) : target(view);
  if (adam_.m.size() != g_.size()) adam_.resetFor(g_);
  if (stats_.count.size() != g_.size()) stats_.resize(g_.size());
  // The gradient is zero here: the last step's Adam cleared it as it read it
  // (adamStepClearingGradient), unless that step stopped before Adam or the model changed.
  if (grad_.size() != g_.size() || grad_.max_sh_degree != g_.max_sh_degree)
    grad_ = g_.zerosLike();
  else if (!grad_cleared_)
    grad_.forEachArray([](std::vector<float>& a, std::size_t) { std::fill(a.begin(), a.end(), 0.0f); });
  grad_cleared_ = false;
  grad2d_.assign(2 * g_.size(), 0.0f);

  const ViewLoss vl = viewLossAndGradient(g_, cam, s, gt, opt_.lambda_ssim, opt_.residual, rng_, grad_, grad2d_,
                                          seconds_, step_buffers_);
  const double loss = vl.loss;
  if (!std::isfinite(loss))
    throw TrainingDiverged(iteration_, view, scene_.views.at(static_cast<std::size_t>(view)).name, "loss",
                           "is " + std::to_string(loss));
  const std::span<const float> radii = vl.radii;
  const std::span<const std::uint8_t> visible = vl.visible;

  auto t0 = Clock::now();
  const DensifyOptions& d = opt_.densify;
  if (d.enabled && iteration_ < d.until_iter)
    accumulateDensifyStats(stats_, grad2d_, radii, visible, cam.K.width, cam.K.height);
  LearningRates lr = opt_.lr;
  const double ext = std::max(scene_.extent, 1e-12);
  lr.means = meansLearningRate(opt_, iteration_, ext);
  adamStepClearingGradient(g_, grad_, adam_, lr);
  grad_cleared_ = true;
  seconds_.optimizer += since(t0);

  t0 = Clock::now();
  if (d.enabled && iteration_ < d.until_iter) {
    if (iteration_ > d.from_iter && d.interval > 0 && iteration_ % d.interval == 0)
      last_densify_ = densifyAndPrune(g_, adam_, stats_, d, ext, iteration_ > d.opacity_reset_interval, rng_);
    // 3DGS's extra reset at densify_from for white-background data: only where the data
    // has an empty background (an enclosed scene has none; Scene::background is unset).
    const bool white = scene_.background && (*scene_.background)[0] == 1.0f && (*scene_.background)[1] == 1.0f &&
                       (*scene_.background)[2] == 1.0f;
    const bool due = (d.opacity_reset_interval > 0 && iteration_ % d.opacity_reset_interval == 0) ||
                     (white && iteration_ == d.from_iter);
    // Outside train() (a bare step()) there is no plan: the schedule applies as is.
    const bool room = plan_end_ == 0 || plan_end_ - iteration_ >= d.min_iterations_after_reset;
    if (due && room) resetOpacity(g_, adam_);
  }
  seconds_.densify += since(t0);
  if (opt_.finite_check_interval > 0 && iteration_ % opt_.finite_check_interval == 0) checkFinite(view);
  return loss;
}

RenderResult Trainer::render(const Camera& cam) const { return rasterize(g_, cam, rasterSettings()); }

Evaluation Trainer::evaluate(const std::vector<int>& views, bool keep_renders, bool with_ssim) const {
  Evaluation e;
  ImageF gt;
  // One render's buffers for every view, and the colour only (no depth or contributor
  // sums: the metrics read neither).
  RasterSettings s = rasterSettings();
  s.depth_and_contributors = false;
  RenderResult r;
  for (int v : views) {
    rasterize(g_, scene_.views.at(static_cast<std::size_t>(v)).camera, s, {}, r);
    toFloatInto(scene_.image(v), gt);
    e.views.push_back({v, psnr(r.rgb, gt), with_ssim ? ssim(r.rgb, gt) : 0.0});
    if (keep_renders) e.renders.push_back(toByte(r.rgb));
    e.psnr += e.views.back().psnr;
    e.ssim += e.views.back().ssim;
  }
  if (!e.views.empty()) {
    e.psnr /= static_cast<double>(e.views.size());
    e.ssim /= static_cast<double>(e.views.size());
  }
  return e;
}

void Trainer::saveCheckpoint(const std::string& path) const {
  writeStreamAtomic(
      path,
      [&](std::ostream& os) {
        Writer w{os};
        os.write(kMagic, sizeof(kMagic));
        w.pod<std::uint64_t>(scene_.views.size());
        w.pod<std::int32_t>(iteration_);
        w.pod<double>(loss_ema_);
        std::ostringstream rs;
        rs << rng_;
        const std::string rng_text = rs.str();
        w.vec(std::vector<char>(rng_text.begin(), rng_text.end()));
        w.vec(view_set_);
        w.vec(view_stack_);
        w.model(g_);
        w.model(adam_.m);
        w.model(adam_.v);
        w.pod<std::int64_t>(adam_.step);
        w.vec(stats_.grad_accum);
        w.vec(stats_.count);
        w.vec(stats_.max_radius);
        w.pod(seconds_);
      },
      true);
}

void Trainer::loadCheckpoint(const std::string& path) {
  const std::string bytes = readFile(path);
  Reader r{bytes, path};
  r.need(sizeof(kMagic), "magic");
  if (std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0)
    throw InputError(path, "magic", "not a saresgs trainer checkpoint (version 1)");
  r.pos = sizeof(kMagic);
  const auto views = r.pod<std::uint64_t>("views");
  if (views != scene_.views.size())
    throw InputError(path, "views",
                     "written for a scene with " + std::to_string(views) + " views, this one has " +
                         std::to_string(scene_.views.size()));
  const int iteration = r.pod<std::int32_t>("iteration");
  if (iteration < 0) throw InputError(path, "iteration", std::to_string(iteration) + " is negative");
  const double ema = r.pod<double>("loss_ema");
  if (!std::isfinite(ema)) throw InputError(path, "loss_ema", "not a finite number");
  const std::vector<char> rng_text = r.vec<char>("rng");
  std::mt19937_64 rng;
  std::istringstream rs(std::string(rng_text.begin(), rng_text.end()));
  rs >> rng;
  if (!rs) throw InputError(path, "rng", "unreadable generator state");
  std::vector<int> view_set = r.vec<int>("view_set"), view_stack = r.vec<int>("view_stack");
  for (int v : view_set)
    if (v < 0 || v >= static_cast<int>(views)) throw InputError(path, "view_set", "view index out of range");
  for (int v : view_stack)
    if (v < 0 || v >= static_cast<int>(views)) throw InputError(path, "view_stack", "view index out of range");
  Gaussians g = r.model("gaussians"), m = r.model("adam.m"), v = r.model("adam.v");
  if (m.size() != g.size() || v.size() != g.size() || m.max_sh_degree != g.max_sh_degree ||
      v.max_sh_degree != g.max_sh_degree)
    throw InputError(path, "adam", "moments do not match the model's shape");
  if (g.max_sh_degree != opt_.max_sh_degree)
    throw InputError(path, "gaussians",
                     "SH degree " + std::to_string(g.max_sh_degree) + " differs from the trainer's " +
                         std::to_string(opt_.max_sh_degree));
  const auto step = r.pod<std::int64_t>("adam.step");
  if (step < 0) throw InputError(path, "adam.step", "negative");
  // NaN or infinity in the model or its moments would poison every later step.
  for (const auto& [model, name] : {std::pair{&g, "gaussians"}, std::pair{&m, "adam.m"}, std::pair{&v, "adam.v"}})
    if (firstNonFinite(*model)) throw InputError(path, name, "holds NaN or infinite values");
  DensifyStats st;
  st.grad_accum = r.vec<float>("stats.grad_accum", g.size());
  st.count = r.vec<std::int32_t>("stats.count", g.size());
  st.max_radius = r.vec<float>("stats.max_radius", g.size());
  const StageSeconds secs = r.pod<StageSeconds>("seconds");
  if (r.pos != bytes.size()) throw InputError(path, "end", "unexpected trailing bytes");
  iteration_ = iteration;
  loss_ema_ = ema;
  rng_ = rng;
  view_set_ = std::move(view_set);
  view_stack_ = std::move(view_stack);
  g_ = std::move(g);
  adam_.m = std::move(m);
  adam_.v = std::move(v);
  adam_.step = step;
  stats_ = std::move(st);
  seconds_ = secs;
}

}  // namespace saresgs
