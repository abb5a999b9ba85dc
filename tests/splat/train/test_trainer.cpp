// The trainer end to end on a tiny synthetic dataset: it learns, it is deterministic,
// a resumed run equals an uninterrupted one bit for bit, reset restores the start, and
// extreme models train without NaN or Inf; and one residual step against its two
// branches run separately.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

#include "splat/raster/raster_test_scenes.h"
#include "common/test_support.h"
#include "splat/loss.h"
#include "splat/train/residual.h"
#include "splat/train/adam.h"
#include "splat/fisher.h"
#include "splat/train/trainer.h"
#include "tests/splat/gaussians_bits.h"

#include <tbb/task_arena.h>
#include <xmmintrin.h>
#include "common/tiny_dataset.h"

namespace saresgs {
namespace {

using test::TempDir;
using test::tinyDataset;

TrainerOptions quickOptions(bool residual = false) {
  TrainerOptions o;
  o.max_sh_degree = 1;
  o.sh_interval = 40;
  o.densify.from_iter = 20;
  o.densify.interval = 20;
  o.densify.opacity_reset_interval = 60;
  o.residual.enabled = residual;
  o.seed = 7;
  return o;
}

bool bitIdentical(const Gaussians& a, const Gaussians& b) {
  if (a.size() != b.size() || a.max_sh_degree != b.max_sh_degree) return false;
  bool same = true;
  std::vector<const std::vector<float>*> arrays;
  a.forEachArray([&](const std::vector<float>& x, std::size_t) { arrays.push_back(&x); });
  std::size_t k = 0;
  b.forEachArray([&](const std::vector<float>& y, std::size_t) {
    const auto& x = *arrays[k++];
    same = same && x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(float)) == 0;
  });
  return same;
}

bool allFiniteModel(const Gaussians& g) {
  bool ok = true;
  g.forEachArray([&](const std::vector<float>& a, std::size_t) {
    for (float x : a) ok = ok && std::isfinite(x);
  });
  return ok;
}

TEST(Trainer, MeansLearningRateDecaysLogLinearly) {
  TrainerOptions o;
  EXPECT_NEAR(meansLearningRate(o, 0, 2.0), 3.2e-4, 1e-10);
  EXPECT_NEAR(meansLearningRate(o, 30000, 2.0), 3.2e-6, 1e-12);
  EXPECT_NEAR(meansLearningRate(o, 15000, 2.0), std::sqrt(3.2e-4 * 3.2e-6), 1e-10);
  EXPECT_NEAR(meansLearningRate(o, 90000, 2.0), 3.2e-6, 1e-12);
}

TEST(Trainer, InitialModelComesFromTheSparsePoints) {
  const Scene& s = tinyDataset();
  Trainer t(s, quickOptions());
  ASSERT_EQ(t.gaussians().size(), s.points.size());
  EXPECT_FLOAT_EQ(t.gaussians().means[0], static_cast<float>(s.points[0].xyz.x()));
  EXPECT_EQ(t.activeShDegree(), 0);
  ASSERT_TRUE(s.background.has_value());  // the manifest's white
  EXPECT_EQ(t.rasterSettings().background[0], 1.0f);
}

TEST(Trainer, WithoutPointsStartsFromRandomPointsWhereTheCamerasLook) {
  Scene s = tinyDataset();
  s.points.clear();
  TrainerOptions o = quickOptions();
  o.random_init_points = 500;
  Trainer t(s, o);
  ASSERT_EQ(t.gaussians().size(), 500u);
  const ViewFocus f = viewFocus(s.cameras(s.train));
  ASSERT_GT(f.radius, 0);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e30), hi = -lo;
  for (std::size_t i = 0; i < 500; ++i) {
    const Eigen::Vector3d p(t.gaussians().means[3 * i], t.gaussians().means[3 * i + 1], t.gaussians().means[3 * i + 2]);
    EXPECT_LE((p - f.center).norm(), f.radius * (1 + 1e-6) + 1e-6);
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  // The points fill the ball, not a corner of it.
  EXPECT_GT((hi - lo).minCoeff(), f.radius);
}

TEST(Trainer, TrainingRaisesTrainPsnr) {
  const Scene& s = tinyDataset();
  Trainer t(s, quickOptions());
  const double before = t.evaluate(s.train).psnr;
  int calls = 0;
  t.train(s.train, 150, [&](const TrainProgress& p) {
    ++calls;
    EXPECT_EQ(p.done, calls);
    EXPECT_TRUE(std::isfinite(p.loss));
  });
  EXPECT_EQ(calls, 150);
  EXPECT_EQ(t.iteration(), 150);
  EXPECT_EQ(t.activeShDegree(), 1);
  const double after = t.evaluate(s.train).psnr;
  EXPECT_GT(after, before + 3.0) << before << " -> " << after;
  // Kept renders are the renders, and keeping them changes no metric.
  const Evaluation kept = t.evaluate(s.train, /*keep_renders=*/true);
  EXPECT_EQ(kept.psnr, after);
  ASSERT_EQ(kept.renders.size(), s.train.size());
  for (std::size_t i = 0; i < s.train.size(); ++i)
    EXPECT_EQ(kept.renders[i].data, toByte(t.render(s.views[static_cast<std::size_t>(s.train[i])].camera).rgb).data);
  EXPECT_TRUE(t.evaluate(s.train).renders.empty());
  EXPECT_NE(t.gaussians().size(), s.points.size());  // densification ran
  EXPECT_TRUE(allFiniteModel(t.gaussians()));
}

// The divergence guard: a non-finite value in the model is found and named (array and
// Gaussian), a step that meets it stops with TrainingDiverged, and learning rates 1e4
// times too large either train finite or stop named, never leave NaN in a finished model.
TEST(Trainer, DivergenceIsStoppedAndNamed) {
  const Scene& s = tinyDataset();
  {
    Trainer t(s, quickOptions());
    t.checkFinite(s.train[0]);  // a fresh model is finite
    t.mutableGaussians().opacities[5] = std::numeric_limits<float>::quiet_NaN();
    try {
      t.checkFinite(s.train[0]);
      ADD_FAILURE() << "a NaN opacity passed the check";
    } catch (const TrainingDiverged& e) {
      EXPECT_EQ(e.quantity(), "opacities");
      EXPECT_NE(std::string(e.what()).find("Gaussian 5 "), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(s.views[s.train[0]].name), std::string::npos) << e.what();
    }
  }
  {
    TrainerOptions o = quickOptions();
    o.finite_check_interval = 1;
    Trainer t(s, o);
    for (float& m : t.mutableGaussians().means) m = std::numeric_limits<float>::infinity();
    EXPECT_THROW(t.step(s.train[0]), TrainingDiverged);
  }
  TrainerOptions o = quickOptions();
  for (float* lr : {&o.lr.means, &o.lr.log_scales, &o.lr.rotations, &o.lr.opacities, &o.lr.sh_dc, &o.lr.sh_rest})
    *lr *= 1e4f;
  Trainer t(s, o);
  bool stopped = false;
  try {
    t.train(s.train, 200);
  } catch (const TrainingDiverged& e) {
    stopped = true;
    EXPECT_GT(e.iteration, 0);
  }
  if (!stopped) {
    EXPECT_TRUE(allFiniteModel(t.gaussians()));
  }
}

TEST(Trainer, SameSeedSameParametersBitForBit) {
  const Scene& s = tinyDataset();
  for (bool residual : {false, true}) {
    Trainer a(s, quickOptions(residual)), b(s, quickOptions(residual));
    a.train(s.train, 70);
    b.train(s.train, 70);
    EXPECT_TRUE(bitIdentical(a.gaussians(), b.gaussians())) << residual;
    TrainerOptions other = quickOptions(residual);
    other.seed = 8;
    Trainer c(s, other);
    c.train(s.train, 70);
    EXPECT_FALSE(bitIdentical(a.gaussians(), c.gaussians())) << residual;
  }
}

TEST(Trainer, ResumedRunEqualsAnUninterruptedOne) {
  const Scene& s = tinyDataset();
  TempDir d;
  for (bool residual : {false, true}) {
    Trainer full(s, quickOptions(residual));
    full.train(s.train, 90);
    Trainer first(s, quickOptions(residual));
    first.train(s.train, 50);  // stops between densification steps, mid view stack
    first.saveCheckpoint(d.file("ckpt.bin"));
    Trainer resumed(s, quickOptions(residual));
    resumed.loadCheckpoint(d.file("ckpt.bin"));
    EXPECT_EQ(resumed.iteration(), 50);
    resumed.train(s.train, 40);
    EXPECT_TRUE(bitIdentical(full.gaussians(), resumed.gaussians())) << residual;
  }
}

TEST(Trainer, ResetRestoresTheInitialModel) {
  const Scene& s = tinyDataset();
  Trainer t(s, quickOptions());
  const Gaussians start = t.gaussians();
  t.train(s.train, 30);
  EXPECT_FALSE(bitIdentical(start, t.gaussians()));
  t.reset();
  EXPECT_EQ(t.iteration(), 0);
  EXPECT_TRUE(bitIdentical(start, t.gaussians()));
  t.train({s.train[0], s.train[1]}, 5);  // a different view set trains fine after reset
  EXPECT_EQ(t.iteration(), 5);
}

TEST(Trainer, BadCheckpointsAreClearErrors) {
  const Scene& s = tinyDataset();
  TempDir d;
  Trainer t(s, quickOptions());
  t.train(s.train, 3);
  t.saveCheckpoint(d.file("c.bin"));
  const std::string bytes = test::readBytes(d.file("c.bin"));
  test::writeBytes(d.file("trunc.bin"), bytes.substr(0, bytes.size() / 2));
  EXPECT_TRUE(test::throwsInputError([&] { t.loadCheckpoint(d.file("trunc.bin")); }, d.file("trunc.bin"), ""));
  test::writeBytes(d.file("junk.bin"), "hello world, not a checkpoint");
  EXPECT_TRUE(test::throwsInputError([&] { t.loadCheckpoint(d.file("junk.bin")); }, d.file("junk.bin"), "magic"));
  Scene fewer = s;
  fewer.views.pop_back();
  fewer.train.erase(std::remove(fewer.train.begin(), fewer.train.end(), static_cast<int>(fewer.views.size())),
                    fewer.train.end());
  fewer.test.erase(std::remove(fewer.test.begin(), fewer.test.end(), static_cast<int>(fewer.views.size())),
                   fewer.test.end());
  Trainer other(fewer, quickOptions());
  EXPECT_TRUE(test::throwsInputError([&] { other.loadCheckpoint(d.file("c.bin")); }, d.file("c.bin"), "views"));
  EXPECT_TRUE(test::throwsInputError([&] { t.loadCheckpoint(d.file("missing.bin")); }, d.file("missing.bin"), ""));
  // The stored iteration follows the 8-byte magic and the 8-byte view count: a flipped
  // sign bit is refused, not planned as two billion iterations.
  std::string flipped = bytes;
  flipped[16 + 3] = static_cast<char>(flipped[16 + 3] | 0x80);
  test::writeBytes(d.file("neg.bin"), flipped);
  EXPECT_TRUE(test::throwsInputError([&] { t.loadCheckpoint(d.file("neg.bin")); }, d.file("neg.bin"), "iteration"));
  // A NaN in the model is refused too (the last float of the file's model block is hard
  // to find by offset, so the model is made with one and saved).
  Trainer nan_model(s, quickOptions());
  nan_model.mutableGaussians().opacities[0] = std::nanf("");
  nan_model.saveCheckpoint(d.file("nan.bin"));
  EXPECT_TRUE(test::throwsInputError([&] { t.loadCheckpoint(d.file("nan.bin")); }, d.file("nan.bin"), "gaussians"));
  EXPECT_THROW(t.train({}, 1), std::invalid_argument);
  EXPECT_THROW(t.train({9999}, 1), std::invalid_argument);
}

TEST(Trainer, ExtremeModelsTrainWithoutNanOrInf) {
  const Scene& s = tinyDataset();
  Trainer t(s, quickOptions(true));
  Gaussians& g = t.mutableGaussians();
  const Camera& cam = s.views[s.train[0]].camera;
  const Eigen::Vector3d c = cam.center(), dir = cam.viewDirection();
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<float> u(-1, 1);
  for (std::size_t i = 0; i < g.size(); ++i) {
    switch (i % 10) {
      case 8:  // a nearly singular covariance: one axis a millionth of the others
        g.log_scales[3 * i] = std::log(1e-6f * static_cast<float>(s.extent));
        g.log_scales[3 * i + 1] = g.log_scales[3 * i + 2] = std::log(0.05f * static_cast<float>(s.extent));
        break;
      case 9:  // huge SH coefficients
        for (std::size_t k = 0; k < g.sh.size() / g.size(); ++k)
          g.sh[i * (g.sh.size() / g.size()) + k] = (k % 2 ? -1e6f : 1e6f);
        break;
      case 0:
        for (int k = 0; k < 3; ++k) g.log_scales[3 * i + k] = std::log(1e-6f * static_cast<float>(s.extent));
        break;
      case 1:
        for (int k = 0; k < 3; ++k) g.log_scales[3 * i + k] = std::log(1e4f * static_cast<float>(s.extent));
        break;
      case 2:
        g.opacities[i] = 30;
        break;
      case 3:
        g.opacities[i] = -30;
        break;
      case 4:
        for (int k = 0; k < 4; ++k) g.rotations[4 * i + k] = 0;
        break;
      case 5:  // at the near plane of the first camera
        for (int k = 0; k < 3; ++k) g.means[3 * i + k] = static_cast<float>(c[k] + 0.0101 * dir[k] + 1e-3 * u(rng));
        break;
      case 6:  // behind it
        for (int k = 0; k < 3; ++k) g.means[3 * i + k] = static_cast<float>(c[k] - 0.5 * dir[k]);
        break;
      default:
        break;
    }
  }
  // Fisher information of the extreme model (what the selectors score) is finite too.
  {
    Gaussians H = g.zerosLike();
    addViewInformation(g, cam, t.rasterSettings(), H);
    EXPECT_TRUE(allFiniteModel(H));
  }
  t.train(s.train, 45);
  EXPECT_TRUE(allFiniteModel(t.gaussians()));
  const RenderResult r = t.render(cam);
  for (float x : r.rgb.data) ASSERT_TRUE(std::isfinite(x));
  Gaussians H = t.gaussians().zerosLike();
  addViewInformation(t.gaussians(), cam, t.rasterSettings(), H);
  EXPECT_TRUE(allFiniteModel(H));
}

// Found by fuzz/fuzz_trainer_checkpoint.cpp (UBSan: memcpy given the null data() of an
// empty vector). The committed input is the checkpoint of a fresh trainer of the fuzz
// fixture's scene (fuzz/fuzz_fixtures.h: 6 views, 8 points, SH degree 1): its view set
// and view stack are empty. It loads, and saving it again gives the same bytes; the
// sanitizers check the same input in the test command's fuzz run (fuzz/run_bounded.sh
// runs every tests/**/fuzz_regressions/<target>/ input).
TEST(Trainer, ACheckpointWithEmptyViewListsLoads) {
  const std::string file = std::string(SARESGS_SOURCE_DIR) +
                           "/tests/splat/train/fuzz_regressions/trainer_checkpoint/fresh_empty_view_lists.bin";
  const Scene s = test::ringScene([](int i) { return std::to_string(i); }, false);
  TrainerOptions o;
  o.max_sh_degree = 1;
  o.random_init_points = 4;
  Trainer t(s, o);
  t.loadCheckpoint(file);
  EXPECT_EQ(t.gaussians().size(), 8u);
  EXPECT_EQ(t.iteration(), 0);
  TempDir d;
  t.saveCheckpoint(d.file("again.bin"));
  EXPECT_EQ(test::readBytes(d.file("again.bin")), test::readBytes(file));
}

TEST(Trainer, NoOpacityResetRightBeforeTheEndOfThePlan) {
  const Scene& s = tinyDataset();
  TrainerOptions o;
  o.max_sh_degree = 0;
  o.densify.from_iter = 10;
  o.densify.interval = 10;
  o.densify.opacity_reset_interval = 30;
  o.densify.min_iterations_after_reset = 20;
  o.seed = 2;
  auto maxOpacity = [](const Gaussians& g) {
    float m = -1e30f;
    for (float x : g.opacities) m = std::max(m, x);
    return 1 / (1 + std::exp(-m));
  };
  // The plan ends at 30: the reset due at 30 is skipped, so opacities end above 0.01
  // (the white background also resets at from_iter = 10, with 20 iterations to go).
  Trainer a(s, o);
  a.train(s.train, 30);
  EXPECT_GT(maxOpacity(a.gaussians()), 0.0101f);
  // Planned to 60 but run in two chunks: the reset at 30 happens, as in one 60-call.
  Trainer b(s, o), c(s, o);
  b.planUntil(60);
  b.train(s.train, 30);
  EXPECT_LE(maxOpacity(b.gaussians()), 0.0101f);
  b.train(s.train, 30);
  c.train(s.train, 60);
  EXPECT_TRUE(bitIdentical(b.gaussians(), c.gaussians()));
}

float maxOpacityOf(const Gaussians& g) {
  float m = -1e30f;
  for (float x : g.opacities) m = std::max(m, x);
  return 1 / (1 + std::exp(-m));
}

// 3DGS's extra reset at densify_from applies to data with a white (empty) background
// only, and like every reset it needs min_iterations_after_reset iterations left in the
// plan: a phase shorter than that keeps its opacities.
TEST(Trainer, WhiteBackgroundResetOnlyWhereTheDataHasABackgroundAndRoomToRecover) {
  const Scene& object = tinyDataset();
  ASSERT_TRUE(object.background.has_value());  // the object layout misses to white
  Scene enclosed = object;
  enclosed.background.reset();  // as a room's manifest says: no background
  TrainerOptions o;
  o.max_sh_degree = 0;
  o.densify.from_iter = 10;
  o.densify.interval = 1000;
  o.densify.opacity_reset_interval = 1000;
  o.densify.min_iterations_after_reset = 20;
  o.seed = 4;
  auto afterTen = [&](const Scene& s, int plan) {
    Trainer t(s, o);
    t.planUntil(plan);
    t.train(s.train, 10);
    return maxOpacityOf(t.gaussians());
  };
  EXPECT_LE(afterTen(object, 40), 0.0101f);    // white data, 30 iterations left: reset
  EXPECT_GT(afterTen(enclosed, 40), 0.0101f);  // no background: no reset
  EXPECT_GT(afterTen(object, 25), 0.0101f);    // 15 left < 20: too short to recover
  EXPECT_LE(afterTen(object, 30), 0.0101f);    // exactly the guard: reset
  // The default guard is one reset interval, and schedules scale it with the rest.
  EXPECT_EQ(DensifyOptions{}.min_iterations_after_reset, DensifyOptions{}.opacity_reset_interval);
}

// The SH degree on an outer clock: after a reset at global iteration 950 with
// sh_interval 100, the degree rises at global 1000, 1100, 1200 (iterations 50, 150, 250
// of the phase), not at 100, 200, 300; reset() returns to the plain schedule.
TEST(Trainer, ShScheduleOnTheGlobalClock) {
  const Scene& s = tinyDataset();
  TrainerOptions o;
  o.max_sh_degree = 3;
  o.sh_interval = 100;
  o.densify.enabled = false;
  Trainer t(s, o);
  t.setShClockStart(950);
  EXPECT_EQ(t.activeShDegree(), 0);
  t.train(s.train, 49);
  EXPECT_EQ(t.activeShDegree(), 0);
  t.train(s.train, 1);
  EXPECT_EQ(t.activeShDegree(), 1);
  t.train(s.train, 200);
  EXPECT_EQ(t.activeShDegree(), 3);
  t.reset();
  t.train(s.train, 99);
  EXPECT_EQ(t.activeShDegree(), 0);
  t.train(s.train, 1);
  EXPECT_EQ(t.activeShDegree(), 1);
}

// The max over an array of |a - b|, against 1e-4 of its largest |a|.
void expectClose(const std::vector<float>& a, const std::vector<float>& b, const char* name) {
  ASSERT_EQ(a.size(), b.size()) << name;
  double scale = 0, diff = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    scale = std::max(scale, static_cast<double>(std::abs(a[k])));
    diff = std::max(diff, static_cast<double>(std::abs(a[k] - b[k])));
  }
  EXPECT_LE(diff, 1e-4 * scale) << name;
}

// A residual step (one pass over both branches, rasterizeWithSubset) against its
// definition, the two branches rendered, scored and back-propagated one after the other:
// the same loss, radii, visibility and generator state exactly, the same gradients to
// float rounding. The sub-only ablation is its one branch, bit for bit.
TEST(Trainer, ResidualStepEqualsItsTwoBranches) {
  const Camera cam = test::smallCamera(48, 40);
  const Gaussians g = test::randomScene<double>(200, 1, 3).cast<float>();
  RasterSettings s;
  s.sh_degree = 1;
  s.background = {0.2f, 0.1f, 0.0f};
  const ImageF target = rasterize(test::randomScene<double>(200, 1, 4).cast<float>(), cam, s).rgb;
  ResidualOptions res;
  res.enabled = true;
  for (bool sub_only : {false, true}) {
    SCOPED_TRACE(sub_only ? "sub only" : "both branches");
    res.sub_only = sub_only;
    std::mt19937_64 rng(9), ref_rng(9);
    Gaussians grad = g.zerosLike(), ref_grad = g.zerosLike();
    std::vector<float> g2d(2 * g.size(), 0.0f), ref_g2d(2 * g.size(), 0.0f);
    StageSeconds secs;
    StepBuffers buffers;
    const ViewLoss L = viewLossAndGradient(g, cam, s, target, 0.2, res, rng, grad, g2d, secs, buffers);

    double ref_loss = 0;
    RenderResult first;
    auto branch = [&](std::span<const std::uint8_t> mask, double w) {
      RenderResult r = rasterize(g, cam, s, mask);
      LossResult l = photometricLoss(r.rgb, target, 0.2, true);
      for (float& x : l.grad.data) x *= static_cast<float>(w);
      rasterizeBackward(g, cam, s, r, l.grad, ref_grad, &ref_g2d);
      ref_loss += w * l.loss;
      if (first.radii.empty()) first = std::move(r);
    };
    const ResidualSubset sub = selectResidualSubset(g, res, ref_rng);
    if (!sub_only) branch({}, res.lambda_full);
    branch(sub.mask, sub_only ? 1.0 : res.lambda_sub);

    EXPECT_EQ(L.loss, ref_loss);
    EXPECT_EQ(std::vector<float>(L.radii.begin(), L.radii.end()), first.radii);
    EXPECT_EQ(std::vector<std::uint8_t>(L.visible.begin(), L.visible.end()), first.visible);
    EXPECT_TRUE(rng == ref_rng);
    if (sub_only) {
      EXPECT_TRUE(bitIdentical(grad, ref_grad));
      EXPECT_EQ(g2d, ref_g2d);
    } else {
      test::forEachArrayPair(ref_grad, grad, expectClose);
      expectClose(ref_g2d, g2d, "mean2d");
    }
  }
}

// Runs f as Embree's BVH builds leave TBB: flush-to-zero and denormals-are-zero set on the
// calling thread while a new task arena starts, so that the arena's workers take that mode
// on for every task (TBB hands the arena's captured floating-point mode to its workers;
// an Embree build that happens to create the process's default arena leaves every later
// parallel loop's workers so, geometry/float_env.h).
template <typename F>
auto withThreadsInFlushToZero(F&& f) {
  const unsigned saved = _mm_getcsr();
  _mm_setcsr(saved | 0x8040u);
  tbb::task_arena arena(2);
  arena.initialize();
  auto r = arena.execute(f);
  _mm_setcsr(saved);
  return r;
}

}  // namespace

// Adam's second moment of a gradient of 1e-20 is 1e-43, a denormal: flushed to zero it
// changes the step (its square root, 1e-20 after bias correction, is 1e-5 of eps). With the
// threads in flush-to-zero mode the update is the IEEE one all the same, bit for bit.
TEST(Trainer, AdamIgnoresTheThreadsFlushToZeroMode) {
  Gaussians p;
  p.resize(5000);
  Gaussians g = p.zerosLike();
  for (std::size_t i = 0; i < g.rotations.size(); ++i) g.rotations[i] = 1e-20f * static_cast<float>(1 + i % 7);
  auto run = [&] {
    Gaussians q = p;
    AdamState s;
    s.resetFor(q);
    for (int k = 0; k < 3; ++k) adamStep(q, g, s, LearningRates{});
    return q.rotations;
  };
  const std::vector<float> ieee = run();
  const std::vector<float> flushed = withThreadsInFlushToZero(run);
  EXPECT_EQ(ieee, flushed) << ieee[0] << " " << flushed[0];
  EXPECT_NE(ieee[0], 0.0f);  // the tiny gradient did move the parameter
}

// Training after something left the worker threads in flush-to-zero mode (in the field:
// making a synthetic scene or Embree-visible sets in the same process, then training)
// trains the same model as a fresh process, bit for bit.
TEST(Trainer, TrainingIgnoresTheThreadsFlushToZeroMode) {
  const Scene& s = tinyDataset();
  auto train = [&] {
    Trainer t(s, quickOptions());
    t.train(s.train, 60);
    return t.gaussians();
  };
  const Gaussians ieee = train();
  const Gaussians flushed = withThreadsInFlushToZero(train);
  EXPECT_EQ(ieee.means, flushed.means);
  EXPECT_EQ(ieee.log_scales, flushed.log_scales);
  EXPECT_EQ(ieee.rotations, flushed.rotations);
  EXPECT_EQ(ieee.opacities, flushed.opacities);
  EXPECT_EQ(ieee.sh, flushed.sh);
}

// The same with residual supervision, whose step runs more of its work as parallel tasks
// (the subset's draw beside its rankings, the two images' losses side by side, the
// binning's chunks, the densification statistics), each opening with a FloatEnvGuard: the
// model is the fresh process's bit for bit. An end-to-end check: on this small scene no
// denormal reaches the losses' own serial code, so it would not notice one guard missing
// there (tried), only a result that changes.
TEST(Trainer, ResidualTrainingIgnoresTheThreadsFlushToZeroMode) {
  const Scene& s = tinyDataset();
  auto train = [&] {
    TrainerOptions o = quickOptions();
    o.residual.enabled = true;
    Trainer t(s, o);
    t.train(s.train, 60);
    return t.gaussians();
  };
  const Gaussians ieee = train();
  const Gaussians flushed = withThreadsInFlushToZero(train);
  EXPECT_TRUE(test::arraysBitEqual(flushed, ieee));
}

}  // namespace saresgs
