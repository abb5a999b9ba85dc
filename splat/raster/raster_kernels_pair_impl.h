// The float tile kernels that composite, and back-propagate, a full render and the render
// of a subset of its Gaussians in one walk (see splat/raster/raster_kernels.h). Included
// right after splat/raster/raster_kernels_impl.h in the same translation unit, with the
// same SARESGS_KERNEL_NS / SARESGS_KERNEL_LANES, and reuses its states and steps (ForwardState,
// BackwardState, backStep, forEachBlock, ...).
//
// Why one walk: a subset Gaussian's alpha at a pixel is the full render's alpha at that
// pixel (rule 8 only removes Gaussians), and the kernels are bound by the exponential, so
// each alpha is evaluated once and fed to two independent compositing states. Each
// branch runs, lane by lane, exactly the operations of the single-render kernel in the
// same order, so the subset's outputs (and gradient sums) are bit-identical to those of
// compositeTile / backwardTile run on the subset's own tile lists. Walked counts are kept
// as full-list positions, which are monotone in the subset's own positions.
#if !defined(SARESGS_KERNEL_NS) || !defined(SARESGS_KERNEL_LANES)
#error "include raster_kernels_impl.h (with its macros) before raster_kernels_pair_impl.h"
#endif

namespace saresgs::raster_kernels::SARESGS_KERNEL_NS {

void compositeTilePair(const TileGaussian<float>* q, const std::uint8_t* in_subset, int nq, int x0, int y0,
                       int x1, int y1, const float bg[3], const ForwardOut& full, const ForwardOut& subset) {
  const int w = x1 - x0, h = y1 - y0;
  ForwardState F, S;
  F.init(w, h);
  S.init(w, h);
  for (int j = 0; j < nq && (F.n_active > 0 || S.n_active > 0); ++j) {
    // A branch whose pixels have all stopped, or a Gaussian outside the subset, changes
    // nothing in that branch (its single-render kernel would have left the loop or never
    // seen the Gaussian).
    const bool do_full = F.n_active > 0, do_sub = S.n_active > 0 && in_subset[j] != 0;
    if (!do_full && !do_sub) continue;
    const ForwardColour fc(q[j], j);
    vi stopped_f = vi{} + 0, stopped_s = vi{} + 0;
    forEachBlock(q[j], x0, y0, x1, y1, [&](int blk, const Lanes& Ln, vf) {
      // masks are -1 where true
      if (do_full) stopped_f -= F.step(F.b[blk], Ln, fc.col0, fc.col1, fc.col2, fc.dep, fc.jf);
      if (do_sub) stopped_s -= S.step(S.b[blk], Ln, fc.col0, fc.col1, fc.col2, fc.dep, fc.jf);
    });
    F.n_active -= hsumInt(stopped_f);
    S.n_active -= hsumInt(stopped_s);
  }
  F.write(x0, y0, w, h, bg, full);
  S.write(x0, y0, w, h, bg, subset);
}

namespace {

template <bool kBg>
void backwardTilePairImpl(const TileGaussian<float>* q, const std::uint8_t* in_subset, int x0, int y0, int x1,
                          int y1, const float bg[3], const BackwardIn& full, const BackwardIn& subset,
                          const std::uint32_t* entry_slot, float* slots_full, float* slots_subset) {
  const int w = x1 - x0, h = y1 - y0;
  BackwardState F, S;
  F.init(x0, y0, w, h, bg, full);
  S.init(x0, y0, w, h, bg, subset);
  const std::uint32_t jmax = F.jmax > S.jmax ? F.jmax : S.jmax;
  for (std::uint32_t jj = jmax; jj-- > 0;) {
    // Beyond a branch's walk, or outside the subset, its single-render kernel writes
    // nothing for this entry (its slot stays 0) and its state does not change.
    const bool do_full = jj < F.jmax, do_sub = jj < S.jmax && in_subset[jj] != 0;
    if (!do_full && !do_sub) continue;
    const TileGaussian<float>& g = q[jj];
    const BackwardColour bc(g, jj);
    GradSums sf = zeroSums(), ss = zeroSums();
    // The pixel loops, one instantiation per set of live branches, so that a Gaussian
    // outside the subset (or beyond a branch's walk) runs the single-branch loop.
    auto walk = [&]<bool kFull, bool kSub>() {
      forEachBlock(g, x0, y0, x1, y1, [&](int blk, const Lanes& Ln, vf dy) {
        vf e, wcol;
        if constexpr (kFull) {
          backStep<kBg>(F.b[blk], Ln, bc.jv, bc.col0, bc.col1, bc.col2, e, wcol);
          addMoments(sf, e, Ln.dx, dy);
          addColours(sf, wcol, F.b[blk]);
        }
        if constexpr (kSub) {
          backStep<kBg>(S.b[blk], Ln, bc.jv, bc.col0, bc.col1, bc.col2, e, wcol);
          addMoments(ss, e, Ln.dx, dy);
          addColours(ss, wcol, S.b[blk]);
        }
      });
    };
    if (do_full && do_sub) walk.template operator()<true, true>();
    else if (do_full) walk.template operator()<true, false>();
    else walk.template operator()<false, true>();
    const std::size_t slot = static_cast<std::size_t>(entry_slot[jj]) * kSlot;
    if (do_full) writeSums(g, sf, slots_full + slot);
    if (do_sub) writeSums(g, ss, slots_subset + slot);
  }
}

}  // namespace

void backwardTilePair(const TileGaussian<float>* q, const std::uint8_t* in_subset, int nq, int x0, int y0, int x1,
                      int y1, const float bg[3], const BackwardIn& full, const BackwardIn& subset,
                      const std::uint32_t* entry_slot, float* slots_full, float* slots_subset) {
  if (nq == 0) return;
  if (bg[0] != 0.0f || bg[1] != 0.0f || bg[2] != 0.0f)
    backwardTilePairImpl<true>(q, in_subset, x0, y0, x1, y1, bg, full, subset, entry_slot, slots_full,
                               slots_subset);
  else
    backwardTilePairImpl<false>(q, in_subset, x0, y0, x1, y1, bg, full, subset, entry_slot, slots_full,
                                slots_subset);
}

}  // namespace saresgs::raster_kernels::SARESGS_KERNEL_NS
