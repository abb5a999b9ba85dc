// Rendering into a kept result (rasterize(..., into), rasterizeWithSubset(..., into)) and
// the other per-step buffers a trainer reuses (photometricLoss(..., into),
// selectResidualSubset(..., into)): every result equals a fresh call's bit for bit,
// whatever the sizes, masks and cameras rendered into the buffers before, and a state
// still shared with an earlier result is never overwritten.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "raster_test_scenes.h"
#include "splat/loss.h"
#include "splat/rasterize.h"
#include "splat/train/residual.h"

using namespace saresgs;

namespace {

template <typename V>
bool sameRenderBits(const V& a, const V& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0);
}

bool sameRender(const RenderResult& a, const RenderResult& b) {
  return a.rgb.width == b.rgb.width && a.rgb.height == b.rgb.height && a.rgb.channels == b.rgb.channels &&
         sameRenderBits(a.rgb.data, b.rgb.data) && sameRenderBits(a.alpha.data, b.alpha.data) &&
         sameRenderBits(a.depth.data, b.depth.data) && sameRenderBits(a.contributors, b.contributors) &&
         sameRenderBits(a.radii, b.radii) && sameRenderBits(a.visible, b.visible);
}

bool sameModel(const Gaussians& a, const Gaussians& b) {
  return sameRenderBits(a.means, b.means) && sameRenderBits(a.log_scales, b.log_scales) && sameRenderBits(a.rotations, b.rotations) &&
         sameRenderBits(a.opacities, b.opacities) && sameRenderBits(a.sh, b.sh);
}

// A loss gradient that depends on every pixel, so backward passes read all of the state.
ImageF ramp(const RenderResult& r) {
  ImageF d(r.rgb.width, r.rgb.height, 3);
  for (std::size_t i = 0; i < d.data.size(); ++i) d.data[i] = 0.01f * static_cast<float>(i % 97) - 0.4f;
  return d;
}

Gaussians backwardOf(const Gaussians& g, const Camera& cam, const RasterSettings& s, const RenderResult& r) {
  Gaussians grad = g.zerosLike();
  rasterizeBackward(g, cam, s, r, ramp(r), grad);
  return grad;
}

std::vector<std::uint8_t> halfMask(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::uint8_t> m(n);
  for (auto& x : m) x = static_cast<std::uint8_t>(rng() & 1);
  return m;
}

// A sequence of renders that grows, shrinks and changes every size a render keeps:
// Gaussians, pixels, tile pairs, masks.
struct Job {
  std::string name;
  const Gaussians* g;
  Camera cam;
  std::vector<std::uint8_t> mask;
};

TEST(RenderReuse, RenderIntoAKeptResultEqualsAFreshRender) {
  const Gaussians big = test::randomScene<double>(400, 2, 3, 1.1).cast<float>();
  const Gaussians small = test::randomScene<double>(60, 2, 4).cast<float>();
  std::vector<Job> jobs = {{"big 64x48", &big, test::smallCamera(64, 48), {}},
                           {"small 24x20", &small, test::smallCamera(24, 20), {}},
                           {"big masked 80x60", &big, test::smallCamera(80, 60), halfMask(big.size(), 1)},
                           {"big 64x48 again", &big, test::smallCamera(64, 48), {}},
                           {"small masked 33x17", &small, test::smallCamera(33, 17), halfMask(small.size(), 2)}};
  for (const auto& [kname, kernels] : test::runnableKernels())
    for (int threads : {1, 2}) {
      RasterSettings s;
      s.sh_degree = 2;
      s.background = {0.2f, 0.1f, 0.3f};
      s.execution.kernels = kernels;
      s.execution.threads = threads;
      RenderResult kept;
      for (const Job& j : jobs) {
        SCOPED_TRACE(std::string(kname) + ", " + std::to_string(threads) + " threads, " + j.name);
        rasterize(*j.g, j.cam, s, j.mask, kept);
        const RenderResult fresh = rasterize(*j.g, j.cam, s, j.mask);
        EXPECT_TRUE(sameRender(kept, fresh));
        EXPECT_TRUE(sameModel(backwardOf(*j.g, j.cam, s, kept), backwardOf(*j.g, j.cam, s, fresh)));
      }
    }
}

TEST(RenderReuse, AStateSharedWithAnEarlierResultIsNotOverwritten) {
  const Gaussians g = test::randomScene<double>(300, 1, 5, 1.2).cast<float>();
  RasterSettings s;
  s.sh_degree = 1;
  const Camera a = test::smallCamera(64, 48);
  const Camera b = test::smallCamera(40, 30);
  RenderResult kept = rasterize(g, a, s);
  const RenderResult earlier = kept;  // shares kept's state
  const Gaussians grad_before = backwardOf(g, a, s, earlier);
  rasterize(g, b, s, {}, kept);  // must not refill the shared state
  ASSERT_NE(kept.state.get(), earlier.state.get());
  EXPECT_TRUE(sameRender(kept, rasterize(g, b, s)));
  EXPECT_TRUE(sameModel(backwardOf(g, a, s, earlier), grad_before));
  EXPECT_TRUE(sameModel(backwardOf(g, b, s, kept), backwardOf(g, b, s, rasterize(g, b, s))));
}

TEST(RenderReuse, RenderPairIntoAKeptPairEqualsAFreshPair) {
  const Gaussians big = test::randomScene<double>(350, 3, 6, 1.2).cast<float>();
  const Gaussians small = test::randomScene<double>(80, 3, 7).cast<float>();
  struct PairJob {
    const Gaussians* g;
    Camera cam;
    std::uint64_t seed;
  };
  const std::vector<PairJob> jobs = {{&big, test::smallCamera(72, 56), 1},
                                     {&small, test::smallCamera(30, 22), 2},
                                     {&big, test::smallCamera(48, 64), 3},
                                     {&big, test::smallCamera(72, 56), 4}};
  for (const auto& [kname, kernels] : test::runnableKernels()) {
    RasterSettings s;
    s.sh_degree = 3;
    s.execution.kernels = kernels;
    s.execution.threads = 2;
    RenderPair kept;
    for (std::size_t k = 0; k < jobs.size(); ++k) {
      SCOPED_TRACE(std::string(kname) + ", job " + std::to_string(k));
      const PairJob& j = jobs[k];
      const std::vector<std::uint8_t> mask = halfMask(j.g->size(), j.seed);
      rasterizeWithSubset(*j.g, j.cam, s, mask, kept);
      const RenderPair fresh = rasterizeWithSubset(*j.g, j.cam, s, mask);
      EXPECT_TRUE(sameRender(kept.full, fresh.full));
      EXPECT_TRUE(sameRender(kept.subset, fresh.subset));
      Gaussians gk = j.g->zerosLike(), gf = j.g->zerosLike();
      std::vector<float> mk, mf;
      const ImageF d = ramp(fresh.full);
      ImageF d2 = d;
      for (float& x : d2.data) x = -0.5f * x;
      rasterizeBackwardWithSubset(*j.g, j.cam, s, kept, d, d2, gk, &mk);
      rasterizeBackwardWithSubset(*j.g, j.cam, s, fresh, d, d2, gf, &mf);
      EXPECT_TRUE(sameModel(gk, gf));
      EXPECT_TRUE(sameRenderBits(mk, mf));
    }
  }
}

TEST(RenderReuse, LossIntoAKeptResultEqualsAFreshLoss) {
  const Gaussians g = test::randomScene<double>(200, 1, 8).cast<float>();
  RasterSettings s;
  s.sh_degree = 1;
  LossResult kept;
  for (const auto& [w, h, want_grad] :
       std::vector<std::tuple<int, int, bool>>{{64, 48, true}, {24, 20, true}, {64, 48, false}, {80, 60, true}}) {
    SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h) + (want_grad ? " with" : " without") + " gradient");
    const Camera cam = test::smallCamera(w, h);
    const ImageF render = rasterize(g, cam, s).rgb;
    ImageF target = render;
    for (std::size_t i = 0; i < target.data.size(); ++i) target.data[i] = 0.3f + 0.002f * static_cast<float>(i % 211);
    photometricLoss(render, target, 0.2, want_grad, kept);
    const LossResult fresh = photometricLoss(render, target, 0.2, want_grad);
    EXPECT_EQ(kept.loss, fresh.loss);
    EXPECT_EQ(kept.l1, fresh.l1);
    EXPECT_EQ(kept.ssim, fresh.ssim);
    EXPECT_EQ(kept.grad.width, fresh.grad.width);
    EXPECT_EQ(kept.grad.height, fresh.grad.height);
    EXPECT_EQ(kept.grad.channels, fresh.grad.channels);
    EXPECT_TRUE(sameRenderBits(kept.grad.data, fresh.grad.data));
  }
}

TEST(RenderReuse, ResidualSubsetIntoAKeptSubsetEqualsAFreshOne) {
  ResidualSubset kept;
  for (const UncertaintyRanking ranking : {UncertaintyRanking::kBoth, UncertaintyRanking::kOpacity,
                                           UncertaintyRanking::kScale, UncertaintyRanking::kRandom})
    for (int n : {500, 40, 0, 900}) {
      SCOPED_TRACE(std::string(toString(ranking)) + ", " + std::to_string(n) + " Gaussians");
      const Gaussians g = test::randomScene<double>(n, 0, static_cast<std::uint64_t>(n) + 11).cast<float>();
      ResidualOptions opt;
      opt.ranking = ranking;
      std::mt19937_64 rng(n), rng_fresh(n);
      selectResidualSubset(g, opt, rng, kept);
      const ResidualSubset fresh = selectResidualSubset(g, opt, rng_fresh);
      EXPECT_EQ(kept.mask, fresh.mask);
      EXPECT_EQ(kept.random, fresh.random);
      EXPECT_EQ(kept.uncertain, fresh.uncertain);
      EXPECT_TRUE(rng == rng_fresh);
    }
}

}  // namespace
