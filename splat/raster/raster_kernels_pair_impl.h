// The float tile kernels that composite, and back-propagate, a full render and the render
// of a subset of its Gaussians in one walk (see splat/raster/raster_kernels.h). Included
// right after splat/raster/raster_kernels_impl.h in the same translation unit, with the
// same SARESGS_KERNEL_NS / SARESGS_KERNEL_LANES, and reuses its helpers (evalLanes,
// tileSpan, blockRowSpan, ...).
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
namespace {

// One compositing state (a render) over a tile, in the single-render kernel's layout.
struct PairForwardState {
  alignas(64) float Tr[kTile * kTile], C0[kTile * kTile], C1[kTile * kTile], C2[kTile * kTile],
      D[kTile * kTile], walked[kTile * kTile], contrib[kTile * kTile];
  int n_active = 0;

  void init(int w, int h) {
    for (int k = 0; k < kTile * kTile; ++k) {
      const bool inside = blockCol(k) < w && blockRow(k) < h;
      Tr[k] = inside ? 1.0f : -1.0f;
      C0[k] = C1[k] = C2[k] = D[k] = walked[k] = contrib[k] = 0.0f;
    }
    n_active = w * h;
  }
  // compositeTile's per-block body (same operations, same order); returns the stop mask.
  inline vi step(int k, const Lanes& Ln, vf col0, vf col1, vf col2, vf dep, vf jf) {
    const vf alpha = Ln.alpha;
    vf t = load(Tr + k);
    const vi ok = (t > vs(0.0f)) & Ln.touches;
    const vf next = t * (vs(1.0f) - alpha);
    const vi stop = ok & (next < vs(kMinT));
    const vi take = ok & ~stop;
    const vf wgt = take ? alpha * t : vs(0.0f);
    store(C0 + k, fma(wgt, col0, load(C0 + k)));
    store(C1 + k, fma(wgt, col1, load(C1 + k)));
    store(C2 + k, fma(wgt, col2, load(C2 + k)));
    store(D + k, fma(wgt, dep, load(D + k)));
    store(Tr + k, take ? next : (stop ? -t : t));
    store(walked + k, take ? jf : load(walked + k));
    store(contrib + k, load(contrib + k) + (take ? vs(1.0f) : vs(0.0f)));
    return stop;
  }
  void write(int x0, int y0, int w, int h, const float bg[3], const ForwardOut& out) const {
    for (int k = 0; k < kTile * kTile; ++k) {
      const int r = blockRow(k), c = blockCol(k);
      if (r >= h || c >= w) continue;
      const float T = std::abs(Tr[k]);
      const std::size_t pix = static_cast<std::size_t>(y0 + r) * out.W + (x0 + c);
      out.rgb[pix * 3] = C0[k] + T * bg[0];
      out.rgb[pix * 3 + 1] = C1[k] + T * bg[1];
      out.rgb[pix * 3 + 2] = C2[k] + T * bg[2];
      out.alpha[pix] = 1.0f - T;
      out.depth[pix] = (1.0f - T) >= 1e-6f ? D[k] / (1.0f - T) : 0.0f;
      out.contributors[pix] = static_cast<int>(contrib[k]);
      out.final_T[pix] = T;
      out.n_walked[pix] = static_cast<std::uint32_t>(walked[k]);
    }
  }
};

}  // namespace

void compositeTilePair(const TileGaussian<float>* q, const std::uint8_t* in_subset, int nq, int x0, int y0,
                       int x1, int y1, const float bg[3], const ForwardOut& full, const ForwardOut& subset) {
  const int w = x1 - x0, h = y1 - y0;
  PairForwardState F, S;
  F.init(w, h);
  S.init(w, h);
  const vf lane_x = laneColCentres(), lane_y = laneRowCentres();
  for (int j = 0; j < nq && (F.n_active > 0 || S.n_active > 0); ++j) {
    const TileGaussian<float>& g = q[j];
    // A branch whose pixels have all stopped, or a Gaussian outside the subset, changes
    // nothing in that branch (its single-render kernel would have left the loop or never
    // seen the Gaussian).
    const bool do_full = F.n_active > 0, do_sub = S.n_active > 0 && in_subset[j] != 0;
    if (!do_full && !do_sub) continue;
    int c0, c1, r0, r1;
    tileSpan(g.mx, g.hx, x0, x1, c0, c1);
    tileSpan(g.my, g.hy, y0, y1, r0, r1);
    if (c0 > c1) continue;
    const vf mx = vs(g.mx), my = vs(g.my), hx = vs(g.hx), hy = vs(g.hy), o = vs(g.o);
    const vf jf = vs(static_cast<float>(j + 1));
    const vf ha = vs(-0.5f) * vs(g.a);
    const vf col0 = vs(g.col[0]), col1 = vs(g.col[1]), col2 = vs(g.col[2]), dep = vs(g.depth);
    vi stopped_f = vi{} + 0, stopped_s = vi{} + 0;
    for (int rb = r0 / kBH; rb <= r1 / kBH; ++rb) {
      int lo, hi;
      blockRowSpan(g, x0, y0, rb, c0, c1, lo, hi);
      if (lo > hi) continue;
      const vf dy = (vs(static_cast<float>(y0 + rb * kBH)) + lane_y) - my;
      const vi row_in = absLe(dy, hy);
      const vf qy = rowQuad(g, dy), by = rowCross(g, dy);
      for (int cb = lo & ~(kBW - 1); cb <= hi; cb += kBW) {
        const int k = (rb * kBX + cb / kBW) * L;
        const Lanes Ln = evalLanes((vs(static_cast<float>(x0 + cb)) + lane_x) - mx, ha, qy, by, o, hx, row_in);
        if (do_full) stopped_f -= F.step(k, Ln, col0, col1, col2, dep, jf);  // masks are -1 where true
        if (do_sub) stopped_s -= S.step(k, Ln, col0, col1, col2, dep, jf);
      }
    }
    F.n_active -= hsumInt(stopped_f);
    S.n_active -= hsumInt(stopped_s);
  }
  F.write(x0, y0, w, h, bg, full);
  S.write(x0, y0, w, h, bg, subset);
}

namespace {

// One back-to-front state (a render and its dL/drgb) over a tile, in backwardTileImpl's
// layout.
struct PairBackwardState {
  alignas(64) float Tr[kTile * kTile], finalT[kTile * kTile], walked[kTile * kTile], acc0[kTile * kTile],
      acc1[kTile * kTile], acc2[kTile * kTile], w0[kTile * kTile], w1[kTile * kTile], w2[kTile * kTile],
      bgdot[kTile * kTile];
  std::uint32_t jmax = 0;

  void init(int x0, int y0, int w, int h, const float bg[3], const BackwardIn& in) {
    jmax = 0;
    for (int k = 0; k < kTile * kTile; ++k) {
      const int r = blockRow(k), c = blockCol(k);
      const bool inside = c < w && r < h;
      const std::size_t pix = inside ? static_cast<std::size_t>(y0 + r) * in.W + (x0 + c) : 0;
      Tr[k] = finalT[k] = inside ? in.final_T[pix] : 1.0f;
      const std::uint32_t nw = inside ? in.n_walked[pix] : 0;
      walked[k] = static_cast<float>(nw);
      jmax = nw > jmax ? nw : jmax;
      acc0[k] = acc1[k] = acc2[k] = 0.0f;
      w0[k] = inside ? in.dL_drgb[pix * 3] : 0.0f;
      w1[k] = inside ? in.dL_drgb[pix * 3 + 1] : 0.0f;
      w2[k] = inside ? in.dL_drgb[pix * 3 + 2] : 0.0f;
      bgdot[k] = bg[0] * w0[k] + bg[1] * w1[k] + bg[2] * w2[k];
    }
  }
};

// One Gaussian's gradient sums over its pixels (backwardTileImpl's s_*).
struct PairSums {
  vf e, x, y, xx, xy, yy, c0, c1, c2;
};

// backwardTileImpl's per-block body (same operations, same order).
template <bool kBg>
inline void backStep(PairBackwardState& B, int k, const Lanes& Ln, vf dy, vf jv, vf col0, vf col1, vf col2,
                     PairSums& s) {
  const vf zero = vs(0.0f), one = vs(1.0f);
  const vf dx = Ln.dx, alpha = Ln.alpha;
  const vi valid = (jv < load(B.walked + k)) & Ln.touches;
  const vf a_eff = valid ? alpha : zero;
  const vf t = load(B.Tr + k) / (one - a_eff);
  store(B.Tr + k, t);
  const vf a0 = load(B.acc0 + k), a1 = load(B.acc1 + k), a2 = load(B.acc2 + k);
  const vf d0 = col0 - a0, d1 = col1 - a1, d2 = col2 - a2;
  const vf ww0 = load(B.w0 + k), ww1 = load(B.w1 + k), ww2 = load(B.w2 + k);
  const vf dLdc = fma(d2, ww2, fma(d1, ww1, d0 * ww0));
  vf dLda = dLdc * t;
  if constexpr (kBg) dLda = dLda - load(B.finalT + k) / (one - alpha) * load(B.bgdot + k);
  store(B.acc0 + k, fma(a_eff, d0, a0));
  store(B.acc1 + k, fma(a_eff, d1, a1));
  store(B.acc2 + k, fma(a_eff, d2, a2));
  const vi gm = valid & (Ln.oG < vs(kMaxA));
  const vf e = gm ? Ln.G * dLda : zero;
  s.e += e;
  const vf ex = e * dx, ey = e * dy;
  s.x += ex;
  s.y += ey;
  s.xx = fma(ex, dx, s.xx);
  s.xy = fma(ex, dy, s.xy);
  s.yy = fma(ey, dy, s.yy);
  const vf wcol = a_eff * t;
  s.c0 = fma(wcol, ww0, s.c0);
  s.c1 = fma(wcol, ww1, s.c1);
  s.c2 = fma(wcol, ww2, s.c2);
}

__attribute__((always_inline)) inline void writeSums(const TileGaussian<float>& g, const PairSums& s, float* sl) {
  const float e = hsum(s.e), ex = hsum(s.x), ey = hsum(s.y), exx = hsum(s.xx), exy = hsum(s.xy), eyy = hsum(s.yy);
  sl[0] = e;
  sl[1] = g.o * (g.a * ex + g.b * ey);
  sl[2] = g.o * (g.b * ex + g.c * ey);
  sl[3] = -0.5f * g.o * exx;
  sl[4] = -g.o * exy;
  sl[5] = -0.5f * g.o * eyy;
  sl[6] = hsum(s.c0);
  sl[7] = hsum(s.c1);
  sl[8] = hsum(s.c2);
}

template <bool kBg>
void backwardTilePairImpl(const TileGaussian<float>* q, const std::uint8_t* in_subset, int x0, int y0, int x1,
                          int y1, const float bg[3], const BackwardIn& full, const BackwardIn& subset,
                          const std::uint32_t* entry_slot, float* slots_full, float* slots_subset) {
  const int w = x1 - x0, h = y1 - y0;
  PairBackwardState F, S;
  F.init(x0, y0, w, h, bg, full);
  S.init(x0, y0, w, h, bg, subset);
  const std::uint32_t jmax = F.jmax > S.jmax ? F.jmax : S.jmax;
  const vf lane_x = laneColCentres(), lane_y = laneRowCentres();
  for (std::uint32_t jj = jmax; jj-- > 0;) {
    // Beyond a branch's walk, or outside the subset, its single-render kernel writes
    // nothing for this entry (its slot stays 0) and its state does not change.
    const bool do_full = jj < F.jmax, do_sub = jj < S.jmax && in_subset[jj] != 0;
    if (!do_full && !do_sub) continue;
    const TileGaussian<float>& g = q[jj];
    int c0, c1, r0, r1;
    tileSpan(g.mx, g.hx, x0, x1, c0, c1);
    tileSpan(g.my, g.hy, y0, y1, r0, r1);
    const vf mx = vs(g.mx), my = vs(g.my), hx = vs(g.hx), hy = vs(g.hy), o = vs(g.o);
    const vf jv = vs(static_cast<float>(jj));
    const vf ha = vs(-0.5f) * vs(g.a);
    const vf col0 = vs(g.col[0]), col1 = vs(g.col[1]), col2 = vs(g.col[2]);
    const vf zero = vs(0.0f);
    PairSums sf{zero, zero, zero, zero, zero, zero, zero, zero, zero};
    PairSums ss = sf;
    // The pixel loops, one instantiation per set of live branches, so that a Gaussian
    // outside the subset (or beyond a branch's walk) runs the single-branch loop.
    auto walk = [&]<bool kFull, bool kSub>() {
      for (int rb = r0 / kBH; rb <= r1 / kBH; ++rb) {
        int lo, hi;
        blockRowSpan(g, x0, y0, rb, c0, c1, lo, hi);
        if (lo > hi) continue;
        const vf dy = (vs(static_cast<float>(y0 + rb * kBH)) + lane_y) - my;
        const vi row_in = absLe(dy, hy);
        const vf qy = rowQuad(g, dy), by = rowCross(g, dy);
        for (int cb = lo & ~(kBW - 1); cb <= hi; cb += kBW) {
          const int k = (rb * kBX + cb / kBW) * L;
          const Lanes Ln = evalLanes((vs(static_cast<float>(x0 + cb)) + lane_x) - mx, ha, qy, by, o, hx, row_in);
          if constexpr (kFull) backStep<kBg>(F, k, Ln, dy, jv, col0, col1, col2, sf);
          if constexpr (kSub) backStep<kBg>(S, k, Ln, dy, jv, col0, col1, col2, ss);
        }
      }
    };
    if (c0 <= c1) {
      if (do_full && do_sub) walk.template operator()<true, true>();
      else if (do_full) walk.template operator()<true, false>();
      else walk.template operator()<false, true>();
    }
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
