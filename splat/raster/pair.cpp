// A full render and the render of a subset of its Gaussians in one pass, forward and
// backward (rasterizeWithSubset, rasterizeBackwardWithSubset: residual supervision). It
// reuses projection and binning and differs only in the tile walks, which run the pair
// kernels (splat/raster/raster_kernels_pair_impl.h).
#include "splat/raster/raster_stages.h"
#include <stdexcept>
#include <utility>

namespace saresgs {

struct SubsetRasterState {
  std::vector<std::uint8_t> mask;             // per Gaussian, as given
  std::vector<std::uint8_t> entry_in_subset;  // per full tile entry: its Gaussian's mask
  std::vector<float> final_T;                 // per pixel, of the subset render
  std::vector<std::uint32_t> n_walked;        // per pixel: full-list entries walked
};

using namespace raster_stage;

void rasterizeWithSubset(const Gaussians& g, const Camera& cam, const RasterSettings& s,
                         std::span<const std::uint8_t> mask, RenderPair& into) {
  if (mask.size() != g.size()) throw std::invalid_argument("rasterizeWithSubset: the mask needs one byte per Gaussian");
  const int W = cam.K.width, H = cam.K.height;
  RenderOutputT<float> full = fromRenderResult(into.full), sub = fromRenderResult(into.subset);
  sub.state.reset();
  std::shared_ptr<RasterStateT<float>> st = reuseOrMake(full.state);
  beginState(*st, s, g.max_sh_degree, W, H);
  const CameraT<float> camT(cam, s.guard_band);

  KeptBuffers<TileCover> kept_cover;
  TileCover& cover = kept_cover.get();
  projectAll(g, camT, {}, W, H, *st, full, cover);
  binAndSort(cover, W, H, *st);

  std::shared_ptr<SubsetRasterState> ss = reuseOrMake(into.subset_state);
  ss->mask.assign(mask.begin(), mask.end());
  ss->entry_in_subset.resize(st->entry_gauss.size());
  for (std::size_t e = 0; e < st->entry_gauss.size(); ++e) ss->entry_in_subset[e] = mask[st->entry_gauss[e]] != 0;
  // Per Gaussian, projection does not depend on the mask, so the subset's radii and
  // visibility are the full render's where the mask keeps the Gaussian (rule 8).
  sub.radii.assign(g.size(), 0.0f);
  sub.visible.assign(g.size(), 0);
  for (std::size_t i = 0; i < g.size(); ++i)
    if (mask[i]) {
      sub.radii[i] = full.radii[i];
      sub.visible[i] = full.visible[i];
    }

  allocateImages(W, H, s.depth_and_contributors, full);
  allocateImages(W, H, s.depth_and_contributors, sub);
  st->final_T.resize(static_cast<std::size_t>(W) * H);
  st->n_walked.resize(static_cast<std::size_t>(W) * H);
  ss->final_T.resize(static_cast<std::size_t>(W) * H);
  ss->n_walked.resize(static_cast<std::size_t>(W) * H);
  const float bg[3] = {s.background[0], s.background[1], s.background[2]};
  const raster_kernels::ForwardOut fo_full = forwardOut(W, full, st->final_T.data(), st->n_walked.data());
  const raster_kernels::ForwardOut fo_sub = forwardOut(W, sub, ss->final_T.data(), ss->n_walked.data());
  const raster_kernels::CompositePairFn kernel = st->kernels->composite_pair;
  forEachTile(*st, W, H, [&](int tile, const std::vector<TileGaussian<float>>& q, int x0, int y0, int x1, int y1) {
    kernel(q.data(), ss->entry_in_subset.data() + st->tile_start[tile], static_cast<int>(q.size()), x0, y0, x1, y1, bg,
           fo_full, fo_sub);
  });

  full.state = std::move(st);
  toRenderResult(std::move(full), into.full);
  toRenderResult(std::move(sub), into.subset);
  into.subset_state = std::move(ss);
}

RenderPair rasterizeWithSubset(const Gaussians& g, const Camera& cam, const RasterSettings& s,
                               std::span<const std::uint8_t> mask) {
  RenderPair out;
  rasterizeWithSubset(g, cam, s, mask, out);
  return out;
}

void rasterizeBackwardWithSubset(const Gaussians& g, const Camera& cam, const RasterSettings& s, const RenderPair& fwd,
                                 const ImageF& dL_drgb_full, const ImageF& dL_drgb_subset, Gaussians& grad,
                                 std::vector<float>* grad_mean2d) {
  const int W = fwd.full.rgb.width, H = fwd.full.rgb.height;
  for (const ImageF* d : {&dL_drgb_full, &dL_drgb_subset})
    if (d->width != W || d->height != H || d->channels != 3)
      throw std::invalid_argument("rasterizeBackwardWithSubset: dL/drgb must match the render (3 channels)");
  if (!fwd.full.state || !fwd.subset_state)
    throw std::invalid_argument("rasterizeBackwardWithSubset: not a rasterizeWithSubset result");
  if (grad_mean2d && grad_mean2d->size() != 2 * g.size()) grad_mean2d->resize(2 * g.size(), 0.0f);
  const RasterStateT<float>& st = *fwd.full.state;
  const SubsetRasterState& ss = *fwd.subset_state;
  const RasterSettings& rs = st.settings;
  const std::size_t n = g.size();
  const std::uint32_t pairs = st.gauss_start[n];
  // One slot per (tile, Gaussian) pair of the full render, holding the sum of both
  // branches' sums (the kernel adds them as it walks; for a Gaussian in the subset its
  // subset entries are the subset render's own, in the same order).
  KeptBuffers<GradSlots> kept;
  float* const slots_p = keptGradSlots(kept, pairs);
  const float bg[3] = {rs.background[0], rs.background[1], rs.background[2]};
  const raster_kernels::BackwardIn in_full{W, st.final_T.data(), st.n_walked.data(), dL_drgb_full.data.data()};
  const raster_kernels::BackwardIn in_sub{W, ss.final_T.data(), ss.n_walked.data(), dL_drgb_subset.data.data()};
  const raster_kernels::BackwardPairFn kernel = st.kernels->backward_pair;
  forEachTile(st, W, H, [&](int tile, const std::vector<TileGaussian<float>>& q, int x0, int y0, int x1, int y1) {
    if (q.empty()) return;
    const std::uint32_t b = st.tile_start[tile];
    kernel(q.data(), ss.entry_in_subset.data() + b, static_cast<int>(q.size()), x0, y0, x1, y1, bg, in_full, in_sub,
           slots_p + static_cast<std::size_t>(b) * kGradSlot);
  });

  // The slots hold both branches' sums, so each Gaussian is chained once. The chain rule
  // (projectBackward) is linear in the projected gradients and costs about as much per
  // Gaussian as its whole walk, so one call instead of one per branch saves ~7 ms of a
  // 256x192, 40k step; the price is rounding: the parameters get chain(full + subset)
  // instead of chain(full) + chain(subset). grad_mean2d gets both branches' 2D-mean
  // gradients, as the two separate passes would add them.
  chainSlots(g, cam, st, slots_p, grad, grad_mean2d);
}

}  // namespace saresgs
