// The float tile kernels that composite, and back-propagate, a full render and the render
// of a subset of its Gaussians in one walk (see splat/raster/raster_kernels.h), for the
// including file's KernelIsa: they reuse the states and steps of
// splat/raster/raster_kernels_impl.h and raster_kernels_backward_impl.h (ForwardState,
// BackwardState, backStep, forEachBlock, ...).
//
// Why one walk: a subset Gaussian's alpha at a pixel is the full render's alpha at that
// pixel (rule 8 only removes Gaussians), and the kernels are bound by the exponential, so
// each alpha is evaluated once and fed to two independent compositing states. Each
// branch runs, lane by lane, exactly the operations of the single-render kernel in the
// same order, so the subset's outputs are bit-identical to those of compositeTile run on
// the subset's own tile lists. The backward adds the two branches' contributions into one
// set of gradient sums as it walks (the trainer descends their sum, and every sum is linear
// in the contributions), so its sums equal the two single backward passes' added, up to
// float rounding. Walked counts are kept as full-list positions, which are monotone in the
// subset's own positions.
#pragma once
#include "splat/raster/raster_kernels_backward_impl.h"

namespace saresgs::raster_kernels {
namespace {
template <bool kAux>
void compositeTilePairImpl(const TileGaussian<float>* q, const std::uint8_t* in_subset, int nq, int x0, int y0, int x1,
                           int y1, const float bg[3], const ForwardOut& full, const ForwardOut& subset) {
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
    // The block loop, one instantiation per set of live branches (as in the backward), so
    // that the loop carries no per-block test of which branches run.
    auto walk = [&]<bool kFull, bool kSub>() {
      forEachBlock(q[j], x0, y0, x1, y1, [&](int blk, const Lanes& Ln, vf) {
        // masks are -1 where true
        if constexpr (kFull) stopped_f -= F.template step<kAux>(F.b[blk], Ln, fc.col0, fc.col1, fc.col2, fc.dep, fc.jf);
        if constexpr (kSub) stopped_s -= S.template step<kAux>(S.b[blk], Ln, fc.col0, fc.col1, fc.col2, fc.dep, fc.jf);
      });
    };
    if (do_full && do_sub)
      walk.template operator()<true, true>();
    else if (do_full)
      walk.template operator()<true, false>();
    else
      walk.template operator()<false, true>();
    F.n_active -= hsumInt(stopped_f);
    S.n_active -= hsumInt(stopped_s);
  }
  F.write<kAux>(x0, y0, w, h, bg, full);
  S.write<kAux>(x0, y0, w, h, bg, subset);
}

// Depth and contributors for both renders or for neither (full.depth decides).
inline void compositeTilePair(const TileGaussian<float>* q, const std::uint8_t* in_subset, int nq, int x0, int y0,
                              int x1, int y1, const float bg[3], const ForwardOut& full, const ForwardOut& subset) {
  if (full.depth)
    compositeTilePairImpl<true>(q, in_subset, nq, x0, y0, x1, y1, bg, full, subset);
  else
    compositeTilePairImpl<false>(q, in_subset, nq, x0, y0, x1, y1, bg, full, subset);
}

template <bool kBg>
void backwardTilePairImpl(const TileGaussian<float>* q, const std::uint8_t* in_subset, int nq, int x0, int y0, int x1,
                          int y1, const float bg[3], const BackwardIn& full, const BackwardIn& subset, float* slots) {
  const int w = x1 - x0, h = y1 - y0;
  BackwardState F, S;
  F.init(x0, y0, w, h, bg, full);
  S.init(x0, y0, w, h, bg, subset);
  const std::uint32_t jmax = F.jmax > S.jmax ? F.jmax : S.jmax;
  // Every entry's slot is written (zeros where neither branch walks it), so the caller
  // needs no cleared buffer.
  zeroSlots(slots, static_cast<int>(jmax), nq);
  for (std::uint32_t jj = jmax; jj-- > 0;) {
    // Beyond a branch's walk, or outside the subset, its single-render kernel adds nothing
    // for this entry and its state does not change.
    const bool do_full = jj < F.jmax, do_sub = jj < S.jmax && in_subset[jj] != 0;
    if (!do_full && !do_sub) {
      zeroSlots(slots, static_cast<int>(jj), static_cast<int>(jj) + 1);
      continue;
    }
    const TileGaussian<float>& g = q[jj];
    const BackwardColour bc(g, jj);
    // One set of sums for both branches: 9 accumulators instead of 18 (which spilled on
    // AVX2's 16 registers), one moment update per block instead of two, and half the
    // slots to write and reduce.
    GradSums s = zeroSums();
    // The pixel loops, one instantiation per set of live branches, so that a Gaussian
    // outside the subset (or beyond a branch's walk) runs the single-branch loop.
    auto walk = [&]<bool kFull, bool kSub>() {
      forEachBlock(g, x0, y0, x1, y1, [&](int blk, const Lanes& Ln, vf dy) {
        if constexpr (kFull && kSub) {
          vf ef, wf, es, ws;
          backStep<kBg>(F.b[blk], Ln, bc.jv, bc.col0, bc.col1, bc.col2, ef, wf);
          backStep<kBg>(S.b[blk], Ln, bc.jv, bc.col0, bc.col1, bc.col2, es, ws);
          addMoments(s, ef + es, Ln.dx, dy);
          addColours(s, wf, F.b[blk]);
          addColours(s, ws, S.b[blk]);
        } else {
          BackwardBlock& B = kFull ? F.b[blk] : S.b[blk];
          vf e, wcol;
          backStep<kBg>(B, Ln, bc.jv, bc.col0, bc.col1, bc.col2, e, wcol);
          addMoments(s, e, Ln.dx, dy);
          addColours(s, wcol, B);
        }
      });
    };
    if (do_full && do_sub)
      walk.template operator()<true, true>();
    else if (do_full)
      walk.template operator()<true, false>();
    else
      walk.template operator()<false, true>();
    writeSums(g, s, slots + static_cast<std::size_t>(jj) * kSlot);
  }
}

inline void backwardTilePair(const TileGaussian<float>* q, const std::uint8_t* in_subset, int nq, int x0, int y0,
                             int x1, int y1, const float bg[3], const BackwardIn& full, const BackwardIn& subset,
                             float* slots) {
  if (nq == 0) return;
  if (bg[0] != 0.0f || bg[1] != 0.0f || bg[2] != 0.0f)
    backwardTilePairImpl<true>(q, in_subset, nq, x0, y0, x1, y1, bg, full, subset, slots);
  else
    backwardTilePairImpl<false>(q, in_subset, nq, x0, y0, x1, y1, bg, full, subset, slots);
}

// This compilation's tile walks (the backward, Fisher and pair kernels) as a KernelSet,
// the other members null (raster_kernels_set_impl.h adds them).
constexpr KernelSet walkKernels() {
  KernelSet s{};
  s.name = KernelIsa::kName;
  s.lanes = L;
  s.backward = backwardTile;
  s.fisher = fisherTile;
  s.composite_pair = compositeTilePair;
  s.backward_pair = backwardTilePair;
  return s;
}

}  // namespace
}  // namespace saresgs::raster_kernels
