// rasterizeWithSubset / rasterizeBackwardWithSubset (the full render and a masked subset
// render in one walk) against the separate calls they replace, for every kernel set this
// CPU runs and for one and two threads: renders bit for bit, gradients to float rounding.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "raster_test_scenes.h"
#include "splat/raster/rasterize_detail.h"
#include "splat/rasterize.h"
#include "tests/splat/gaussians_bits.h"

using namespace saresgs;

namespace {

struct PairCase {
  std::string name;
  Gaussians g;
  Camera cam;
  RasterSettings s;
  std::vector<std::uint8_t> mask;
  // False where the float gradients are rounding-dominated: on the stiff scene the
  // separate float passes differ from the double path by more than the largest gradient
  // (needles and 1e4-scale Gaussians), so summing the branches before the chain rule
  // moves them by as much; there only finiteness and determinism are checked.
  bool well_conditioned = true;
};

// ~90 % of the Gaussians, drawn with `seed`, as the residual subset's random part.
std::vector<std::uint8_t> randomMask(std::size_t n, std::uint64_t seed, double keep = 0.9) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<std::uint8_t> m(n);
  for (auto& x : m) x = u(rng) < keep;
  return m;
}

std::vector<PairCase> cases() {
  std::vector<PairCase> out;
  {
    PairCase c{"dense sh2 background",
               test::randomScene<double>(300, 2, 9, 1.2).cast<float>(),
               test::smallCamera(72, 56),
               {},
               {}};
    c.s.sh_degree = 2;
    c.s.background = {0.1f, 0.2f, 0.3f};
    c.mask = randomMask(c.g.size(), 1);
    out.push_back(std::move(c));
  }
  {
    PairCase c{"sh3 no background, sparse mask",
               test::randomScene<double>(120, 3, 5).cast<float>(),
               test::smallCamera(64, 48),
               {},
               {}};
    c.s.sh_degree = 3;
    c.mask = randomMask(c.g.size(), 2, 0.5);
    out.push_back(std::move(c));
  }
  {
    // Opaque, overlapping Gaussians: pixels stop early (T < 1e-4) in the full render and
    // later, or not at all, in the subset.
    PairCase c{"opaque early stop",
               test::randomScene<double>(400, 0, 11, 0.4).cast<float>(),
               test::smallCamera(48, 40),
               {},
               {}};
    for (auto& o : c.g.opacities) o = 6.0f;
    c.s.background = {1.0f, 0.0f, 0.5f};
    c.mask = randomMask(c.g.size(), 3);
    out.push_back(std::move(c));
  }
  {
    // Stiff: opacity logits of +-30, scales from 1e-6 to 1e4 of the scene, needles.
    PairCase c{"stiff", test::randomScene<double>(60, 1, 30).cast<float>(), test::smallCamera(40, 32), {}, {}};
    for (std::size_t i = 0; i < c.g.size(); ++i) {
      if (i % 5 == 0) c.g.opacities[i] = (i % 10) ? 30.0f : -30.0f;
      if (i % 7 == 1)
        for (int k = 0; k < 3; ++k) c.g.log_scales[3 * i + k] = std::log(3e-6f);
      if (i % 7 == 2) c.g.log_scales[3 * i] = std::log(3e4f);
      if (i % 7 == 3) {
        c.g.log_scales[3 * i] = std::log(3e-6f);
        c.g.log_scales[3 * i + 1] = std::log(1.5f);
      }
    }
    c.s.sh_degree = 1;
    c.s.background = {0.1f, 0.2f, 0.3f};
    c.mask = randomMask(c.g.size(), 4);
    c.well_conditioned = false;
    out.push_back(std::move(c));
  }
  {
    PairCase c{"empty subset", test::randomScene<double>(80, 0, 12).cast<float>(), test::smallCamera(40, 32), {}, {}};
    c.mask.assign(c.g.size(), 0);
    out.push_back(std::move(c));
  }
  {
    PairCase c{"whole model", test::randomScene<double>(80, 0, 13).cast<float>(), test::smallCamera(40, 32), {}, {}};
    c.mask.assign(c.g.size(), 1);
    out.push_back(std::move(c));
  }
  return out;
}

void expectSameRender(const RenderResult& a, const RenderResult& b) {
  EXPECT_TRUE(a.rgb.data == b.rgb.data);
  EXPECT_TRUE(a.alpha.data == b.alpha.data);
  EXPECT_TRUE(a.depth.data == b.depth.data);
  EXPECT_TRUE(a.contributors == b.contributors);
  EXPECT_TRUE(a.radii == b.radii);
  EXPECT_TRUE(a.visible == b.visible);
}

ImageF lossImage(int w, int h, std::uint64_t seed, float scale) {
  ImageF img;
  img.width = w;
  img.height = h;
  img.channels = 3;
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> nd(0, 1);
  img.data.resize(static_cast<std::size_t>(w) * h * 3);
  for (float& x : img.data) x = scale * nd(rng);
  return img;
}

struct Grads {
  Gaussians grad;
  std::vector<float> mean2d;
  bool operator==(const Grads& o) const {
    return mean2d == o.mean2d && grad.means == o.grad.means && grad.log_scales == o.grad.log_scales &&
           grad.rotations == o.grad.rotations && grad.opacities == o.grad.opacities && grad.sh == o.grad.sh;
  }
};

}  // namespace

TEST(SubsetPair, RendersAreBitIdenticalToSeparateRenders) {
  for (PairCase& c : cases()) {
    SCOPED_TRACE(c.name);
    for (const auto& [kname, kernels] : test::runnableKernels()) {
      SCOPED_TRACE(kname);
      for (int threads : {1, 2}) {
        SCOPED_TRACE(threads);
        c.s.execution.kernels = kernels;
        c.s.execution.threads = threads;
        const RenderPair p = rasterizeWithSubset(c.g, c.cam, c.s, c.mask);
        expectSameRender(p.full, rasterize(c.g, c.cam, c.s));
        expectSameRender(p.subset, rasterize(c.g, c.cam, c.s, c.mask));
      }
    }
  }
}

// The subset differs from the full render in these scenes (the comparison above is not
// vacuous), except where the mask keeps everything.
TEST(SubsetPair, SubsetRenderDiffersFromTheFullRender) {
  for (PairCase& c : cases()) {
    if (c.name == "whole model") continue;
    SCOPED_TRACE(c.name);
    const RenderPair p = rasterizeWithSubset(c.g, c.cam, c.s, c.mask);
    EXPECT_FALSE(p.subset.rgb.data == p.full.rgb.data);
  }
}

// The pair backward against two separate backward passes: equal up to the rounding of
// summing each Gaussian's two projected gradients before the chain rule, and
// bit-identical across runs and thread counts.
TEST(SubsetPair, BackwardEqualsTwoSeparateBackwardPasses) {
  for (PairCase& c : cases()) {
    SCOPED_TRACE(c.name);
    const int W = c.cam.K.width, H = c.cam.K.height;
    // The weights lambda_full = lambda_sub = 0.5 are folded into the images, as the
    // trainer does.
    const ImageF dl_full = lossImage(W, H, 21, 0.5f), dl_sub = lossImage(W, H, 22, 0.5f);
    for (const auto& [kname, kernels] : test::runnableKernels()) {
      SCOPED_TRACE(kname);
      c.s.execution.kernels = kernels;
      auto separate = [&](int threads) {
        c.s.execution.threads = threads;
        Grads r{c.g.zerosLike(), std::vector<float>(2 * c.g.size(), 0.0f)};
        const RenderResult full = rasterize(c.g, c.cam, c.s);
        rasterizeBackward(c.g, c.cam, c.s, full, dl_full, r.grad, &r.mean2d);
        const RenderResult sub = rasterize(c.g, c.cam, c.s, c.mask);
        rasterizeBackward(c.g, c.cam, c.s, sub, dl_sub, r.grad, &r.mean2d);
        return r;
      };
      auto fused = [&](int threads) {
        c.s.execution.threads = threads;
        Grads r{c.g.zerosLike(), std::vector<float>(2 * c.g.size(), 0.0f)};
        const RenderPair p = rasterizeWithSubset(c.g, c.cam, c.s, c.mask);
        rasterizeBackwardWithSubset(c.g, c.cam, c.s, p, dl_full, dl_sub, r.grad, &r.mean2d);
        return r;
      };
      const Grads ref = separate(2), got = fused(2);
      // Per array, relative to its largest entry: float roundings of terms that may be
      // larger than the result (cancellation in the chain rule); the float path's own
      // error against double is allowed 2e-3 (tests/splat/raster/test_rasterizer.cpp).
      const bool compare = c.well_conditioned;
      auto close = [compare](const std::vector<float>& a, const std::vector<float>& b, const char* name) {
        ASSERT_EQ(a.size(), b.size()) << name;
        double scale = 0, diff = 0;
        for (std::size_t k = 0; k < a.size(); ++k) {
          EXPECT_TRUE(std::isfinite(b[k])) << name << "[" << k << "]";
          scale = std::max(scale, static_cast<double>(std::abs(a[k])));
          diff = std::max(diff, static_cast<double>(std::abs(a[k] - b[k])));
        }
        if (compare) {
          EXPECT_LE(diff, 1e-4 * scale) << name;
        }
      };
      test::forEachArrayPair(ref.grad, got.grad, close);
      close(ref.mean2d, got.mean2d, "mean2d");
      EXPECT_TRUE(fused(1) == got);
      EXPECT_TRUE(fused(2) == got);
      EXPECT_TRUE(fused(0) == got);
    }
  }
}

// The avx512 set's pair backward (the AVX2 kernel on 32 registers) gives the avx2 set's
// gradients bit for bit, on every case, one thread and all.
TEST(SubsetPair, Avx512BackwardEqualsAvx2BitForBit) {
  if (!rasterCpuHasAvx512()) GTEST_SKIP() << "no AVX-512F and AVX-512VL on this CPU (the avx512 set cannot run here)";
  int nonzero = 0;
  for (PairCase& c : cases()) {
    SCOPED_TRACE(c.name);
    const int W = c.cam.K.width, H = c.cam.K.height;
    const ImageF dl_full = lossImage(W, H, 31, 0.5f), dl_sub = lossImage(W, H, 32, 0.5f);
    for (const int threads : {1, 0}) {
      SCOPED_TRACE(threads);
      c.s.execution.threads = threads;
      auto run = [&](RasterKernels kernels) {
        c.s.execution.kernels = kernels;
        Grads r{c.g.zerosLike(), std::vector<float>(2 * c.g.size(), 0.0f)};
        const RenderPair p = rasterizeWithSubset(c.g, c.cam, c.s, c.mask);
        rasterizeBackwardWithSubset(c.g, c.cam, c.s, p, dl_full, dl_sub, r.grad, &r.mean2d);
        return test::flattened(r.mean2d, r.grad);
      };
      const std::vector<float> a = run(RasterKernels::kAvx2), b = run(RasterKernels::kAvx512);
      ASSERT_TRUE(test::valuesBitEqual(b, a, "avx512", "avx2"));
      nonzero += static_cast<int>(std::count_if(a.begin(), a.end(), [](float v) { return v != 0.0f; }));
    }
  }
  EXPECT_GT(nonzero, 1000);  // the comparison saw real gradients
}

// The summed float gradient against the same two branches computed in double (the
// double instantiation of the separate passes), to float precision.
TEST(SubsetPair, BackwardMatchesTheDoublePath) {
  const Camera cam = test::smallCamera(64, 48);
  const GaussiansD gd = test::randomScene<double>(150, 1, 7, 1.5);
  const Gaussians gf = gd.cast<float>();
  RasterSettings s;
  s.sh_degree = 1;
  s.background = {0.3f, 0.15f, 0.7f};
  const std::vector<std::uint8_t> mask = randomMask(gf.size(), 8);
  const ImageF dl_full = lossImage(64, 48, 31, 0.5f), dl_sub = lossImage(64, 48, 32, 0.5f);
  const std::vector<double> wf(dl_full.data.begin(), dl_full.data.end()), ws(dl_sub.data.begin(), dl_sub.data.end());
  GaussiansD gradd = gd.zerosLike();
  std::vector<double> m2d(2 * gd.size(), 0.0);
  rasterizeBackwardT(gd, cam, s, rasterizeT(gd, cam, s), wf.data(), gradd, &m2d);
  rasterizeBackwardT(gd, cam, s, rasterizeT(gd, cam, s, mask), ws.data(), gradd, &m2d);
  for (const auto& [kname, kernels] : test::runnableKernels()) {
    SCOPED_TRACE(kname);
    s.execution.kernels = kernels;
    Gaussians gradf = gf.zerosLike();
    std::vector<float> m2f(2 * gf.size(), 0.0f);
    const RenderPair p = rasterizeWithSubset(gf, cam, s, mask);
    rasterizeBackwardWithSubset(gf, cam, s, p, dl_full, dl_sub, gradf, &m2f);
    auto compare = [](const std::vector<double>& a, const std::vector<float>& b, const char* name) {
      double scale = 0, diff = 0;
      for (std::size_t k = 0; k < a.size(); ++k) {
        scale = std::max(scale, std::abs(a[k]));
        diff = std::max(diff, std::abs(a[k] - b[k]));
      }
      EXPECT_GT(scale, 0.0) << name;
      EXPECT_LE(diff, 2e-3 * scale + 1e-6) << name;
    };
    test::forEachArrayPair(gradd, gradf, compare);
    compare(m2d, m2f, "mean2d");
  }
}

TEST(SubsetPair, RejectsBadInputs) {
  const Camera cam = test::smallCamera(24, 20);
  const Gaussians g = test::randomScene<double>(10, 0, 3).cast<float>();
  RasterSettings s;
  EXPECT_THROW(rasterizeWithSubset(g, cam, s, std::vector<std::uint8_t>(9, 1)), std::invalid_argument);
  const RenderPair p = rasterizeWithSubset(g, cam, s, std::vector<std::uint8_t>(10, 1));
  Gaussians grad = g.zerosLike();
  const ImageF dl = lossImage(24, 20, 1, 1.0f);
  // The subset render has no state of its own: only the pair's backward runs it.
  EXPECT_THROW(rasterizeBackward(g, cam, s, p.subset, dl, grad), std::invalid_argument);
  EXPECT_THROW(rasterizeBackwardWithSubset(g, cam, s, p, dl, lossImage(20, 20, 1, 1.0f), grad), std::invalid_argument);
}

// RasterSettings::depth_and_contributors = false (a training step's renders): depth and
// contributors are left empty, and every other output of the single and the pair render,
// and the gradients their backward passes give, are those of the full render bit for bit,
// for every kernel set, one and two threads, and into reused results in either order.
TEST(SubsetPair, LeavingOutDepthAndContributorsChangesNothingElse) {
  for (PairCase& c : cases()) {
    SCOPED_TRACE(c.name);
    const int W = c.cam.K.width, H = c.cam.K.height;
    const ImageF dl_full = lossImage(W, H, 41, 0.5f), dl_sub = lossImage(W, H, 42, 0.5f);
    for (const auto& [kname, kernels] : test::runnableKernels()) {
      SCOPED_TRACE(kname);
      for (int threads : {1, 2}) {
        SCOPED_TRACE(threads);
        RasterSettings on = c.s;
        on.execution.kernels = kernels;
        on.execution.threads = threads;
        RasterSettings off = on;
        off.depth_and_contributors = false;
        auto expectLeftOut = [&](const RenderResult& r) {
          EXPECT_TRUE(r.depth.data.empty());
          EXPECT_EQ(r.depth.width, 0);
          EXPECT_EQ(r.depth.height, 0);
          EXPECT_TRUE(r.contributors.empty());
          EXPECT_EQ(r.rgb.width, W);
          EXPECT_EQ(r.alpha.height, H);
        };
        auto expectSameButLeftOut = [&](const RenderResult& full, const RenderResult& lean) {
          expectLeftOut(lean);
          EXPECT_TRUE(full.rgb.data == lean.rgb.data);
          EXPECT_TRUE(full.alpha.data == lean.alpha.data);
          EXPECT_TRUE(full.radii == lean.radii);
          EXPECT_TRUE(full.visible == lean.visible);
          // The comparison is not vacuous: the full render has them.
          EXPECT_EQ(full.depth.data.size(), static_cast<std::size_t>(W) * H);
          EXPECT_EQ(full.contributors.size(), static_cast<std::size_t>(W) * H);
        };
        // The single render, fresh and into a result that held a full render (and back).
        const RenderResult single_on = rasterize(c.g, c.cam, on);
        RenderResult reused = rasterize(c.g, c.cam, on);
        rasterize(c.g, c.cam, off, {}, reused);
        expectSameButLeftOut(single_on, reused);
        expectSameButLeftOut(single_on, rasterize(c.g, c.cam, off));
        rasterize(c.g, c.cam, on, {}, reused);
        expectSameRender(single_on, reused);
        auto singleGrads = [&](const RasterSettings& s) {
          Grads r{c.g.zerosLike(), std::vector<float>(2 * c.g.size(), 0.0f)};
          const RenderResult f = rasterize(c.g, c.cam, s);
          rasterizeBackward(c.g, c.cam, s, f, dl_full, r.grad, &r.mean2d);
          return r;
        };
        EXPECT_TRUE(singleGrads(on) == singleGrads(off));
        // The pair.
        const RenderPair pair_on = rasterizeWithSubset(c.g, c.cam, on, c.mask);
        RenderPair pair_reused = rasterizeWithSubset(c.g, c.cam, on, c.mask);
        rasterizeWithSubset(c.g, c.cam, off, c.mask, pair_reused);
        expectSameButLeftOut(pair_on.full, pair_reused.full);
        expectSameButLeftOut(pair_on.subset, pair_reused.subset);
        rasterizeWithSubset(c.g, c.cam, on, c.mask, pair_reused);
        expectSameRender(pair_on.full, pair_reused.full);
        expectSameRender(pair_on.subset, pair_reused.subset);
        auto pairGrads = [&](const RasterSettings& s) {
          Grads r{c.g.zerosLike(), std::vector<float>(2 * c.g.size(), 0.0f)};
          const RenderPair p = rasterizeWithSubset(c.g, c.cam, s, c.mask);
          rasterizeBackwardWithSubset(c.g, c.cam, s, p, dl_full, dl_sub, r.grad, &r.mean2d);
          return r;
        };
        EXPECT_TRUE(pairGrads(on) == pairGrads(off));
      }
    }
  }
  // The generic (double) path leaves them out too.
  const std::vector<PairCase> all = cases();
  const PairCase& c = all.front();
  RasterSettings off = c.s;
  off.depth_and_contributors = false;
  const GaussiansD gd = c.g.cast<double>();
  const auto on_d = rasterizeT(gd, c.cam, c.s), off_d = rasterizeT(gd, c.cam, off);
  EXPECT_TRUE(off_d.depth.empty());
  EXPECT_TRUE(off_d.contributors.empty());
  EXPECT_FALSE(on_d.depth.empty());
  EXPECT_TRUE(on_d.rgb == off_d.rgb);
}
