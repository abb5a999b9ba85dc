// The float tile kernels' backward pass and FisherRF's squared-gradient pass (see
// splat/raster/raster_kernels.h). Built on splat/raster/raster_kernels_impl.h's lanes,
// exponentials and tile walk (Lanes, evalLanes, forEachBlock), for the same KernelIsa; the
// pair kernels (splat/raster/raster_kernels_pair_impl.h) reuse its states.
#pragma once
#include "splat/raster/raster_kernels_impl.h"

namespace saresgs::raster_kernels {
namespace {

// --- Backward -----------------------------------------------------------------------
// Pairwise lane sums of two vectors: [a0 + a1, a2 + a3, ..., b0 + b1, b2 + b3, ...].
// (A template, so that the shuffle of the other lane count is never instantiated.)
template <typename V>
inline V pairSums(V a, V b) {
  if constexpr (L == 4)
    return __builtin_shufflevector(a, b, 0, 2, 4, 6) + __builtin_shufflevector(a, b, 1, 3, 5, 7);
  else
    return __builtin_shufflevector(a, b, 0, 2, 4, 6, 8, 10, 12, 14) +
           __builtin_shufflevector(a, b, 1, 3, 5, 7, 9, 11, 13, 15);
}

// The lane sums of L vectors v[0, L) as one vector (lane k: the sum of v[k]), in a
// fixed tree order (the same tree as hsum): L - 1 shuffle-adds instead of L horizontal
// sums of a dozen scalar instructions each, paid per (tile, Gaussian) pair, while the
// small Gaussians of a trained model cover a tile in a few blocks.
inline vf transposeSums(const vf* v) {
  if constexpr (L == 4)
    return pairSums(pairSums(v[0], v[1]), pairSums(v[2], v[3]));
  else
    return pairSums(pairSums(pairSums(v[0], v[1]), pairSums(v[2], v[3])),
                    pairSums(pairSums(v[4], v[5]), pairSums(v[6], v[7])));
}

// One vector block of a tile's back-to-front state: the transmittance in front of the
// current entry, the pixel's final transmittance and walk length, the colour composited
// behind (normalised), and dL/drgb with its dot product with the background.
struct BackwardBlock {
  vf Tr, finalT, walked, acc0, acc1, acc2, w0, w1, w2, bgdot;
};

struct BackwardState {
  BackwardBlock b[kBlocks];
  std::uint32_t jmax = 0;  // the longest walk: entries from it on are never reached

  void init(int x0, int y0, int w, int h, const float bg[3], const BackwardIn& in) {
    jmax = 0;
    if (w == kTile && h == kTile) {
      // A whole tile, a block at a time: the per-pixel loop below, lane by lane, with
      // vector loads (its lane-by-lane stores made each later full-width load of the
      // state wait).
      const std::size_t W = static_cast<std::size_t>(in.W);
      vi jm = vi{} + 0;
      for (int blk = 0; blk < kBlocks; ++blk) {
        BackwardBlock& B = b[blk];
        const std::size_t pix = static_cast<std::size_t>(y0 + blk / kBX * kBH) * W + (x0 + blk % kBX * kBW);
        B.Tr = B.finalT = loadRows<v4f, vf>(in.final_T + pix, W);
        const vi nw = loadRows<v4i, vi>(reinterpret_cast<const std::int32_t*>(in.n_walked + pix), W);
        B.walked = __builtin_convertvector(nw, vf);
        jm = jm > nw ? jm : nw;
        v4f r[2], g[2], bl[2];
        for (int half = 0; half < kBH; ++half)
          deinterleave3(in.dL_drgb + (pix + half * W) * 3, r[half], g[half], bl[half]);
        B.w0 = joinRows(r[0], r[kBH - 1]);
        B.w1 = joinRows(g[0], g[kBH - 1]);
        B.w2 = joinRows(bl[0], bl[kBH - 1]);
        B.acc0 = B.acc1 = B.acc2 = vs(0.0f);
        B.bgdot = vs(bg[0]) * B.w0 + vs(bg[1]) * B.w1 + vs(bg[2]) * B.w2;
      }
      for (int i = 0; i < L; ++i)
        jmax = static_cast<std::uint32_t>(jm[i]) > jmax ? static_cast<std::uint32_t>(jm[i]) : jmax;
      return;
    }
    for (int k = 0; k < kTile * kTile; ++k) {
      const int r = blockRow(k), c = blockCol(k);
      const bool inside = c < w && r < h;
      const std::size_t pix = inside ? static_cast<std::size_t>(y0 + r) * in.W + (x0 + c) : 0;
      BackwardBlock& B = b[k / L];
      const int i = k % L;
      B.Tr[i] = B.finalT[i] = inside ? in.final_T[pix] : 1.0f;
      const std::uint32_t nw = inside ? in.n_walked[pix] : 0;
      B.walked[i] = static_cast<float>(nw);
      jmax = nw > jmax ? nw : jmax;
      B.acc0[i] = B.acc1[i] = B.acc2[i] = 0.0f;
      B.w0[i] = inside ? in.dL_drgb[pix * 3] : 0.0f;
      B.w1[i] = inside ? in.dL_drgb[pix * 3 + 1] : 0.0f;
      B.w2[i] = inside ? in.dL_drgb[pix * 3 + 2] : 0.0f;
      B.bgdot[i] = bg[0] * B.w0[i] + bg[1] * B.w1[i] + bg[2] * B.w2[i];
    }
  }
};

// One Gaussian's sums over its pixels of e = G dL/dalpha (where alpha = o G is not
// clamped) times 1, dx, dy, dx^2, dx dy, dy^2, and of alpha T w_c; its 2D gradients are
// linear in them (writeSums).
struct GradSums {
  vf e, x, y, xx, xy, yy, c0, c1, c2;
};

// The scalar walkBack of raster_stages.h for one Gaussian (entry jv) at one block, per
// lane: updates the block's state and gives the contribution's e = G dL/dalpha (0 where
// alpha is clamped or the entry does not touch the pixel) and colour weight alpha T.
// kBg: the background term of dL/dalpha; without a background it is exactly 0 and its
// division is skipped.
template <bool kBg>
inline void backStep(BackwardBlock& B, const Lanes& Ln, vf jv, vf col0, vf col1, vf col2, vf& e, vf& wcol) {
  const vf one = vs(1.0f);
  const vf alpha = Ln.alpha;
  const vi valid = (jv < B.walked) & Ln.touches;
  const vf a_eff = maskOr0(valid, alpha);
  const vf t = B.Tr / (one - a_eff);  // transmittance in front of jj
  B.Tr = t;
  // acc: the colour composited behind jj (normalised), updated once jj is used.
  const vf a0 = B.acc0, a1 = B.acc1, a2 = B.acc2;
  const vf d0 = col0 - a0, d1 = col1 - a1, d2 = col2 - a2;
  const vf dLdc = fma(d2, B.w2, fma(d1, B.w1, d0 * B.w0));
  vf dLda = dLdc * t;
  if constexpr (kBg) dLda = dLda - B.finalT / (one - alpha) * B.bgdot;
  B.acc0 = fma(a_eff, d0, a0);
  B.acc1 = fma(a_eff, d1, a1);
  B.acc2 = fma(a_eff, d2, a2);
  const vi gm = valid & (Ln.oG < vs(kMaxA));
  e = maskOr0(gm, Ln.G * dLda);
  wcol = a_eff * t;  // 0 where not valid
}

// A contribution's terms of the sums (each sum's own sequence of operations, whichever
// loop adds them).
inline void addMoments(GradSums& s, vf e, vf dx, vf dy) {
  s.e += e;
  const vf ex = e * dx, ey = e * dy;
  s.x += ex;
  s.y += ey;
  s.xx = fma(ex, dx, s.xx);
  s.xy = fma(ex, dy, s.xy);
  s.yy = fma(ey, dy, s.yy);
}
inline void addColours(GradSums& s, vf wcol, const BackwardBlock& B) {
  s.c0 = fma(wcol, B.w0, s.c0);
  s.c1 = fma(wcol, B.w1, s.c1);
  s.c2 = fma(wcol, B.w2, s.c2);
}

// The 9 slot values of one (tile, Gaussian) pair from its sums: opacity, mean2d (2),
// conic (3), colour (3). dL/dpower = o e; power = -(a dx^2 + 2 b dx dy + c dy^2) / 2
// with dx = px - mean. The lane sums are hsum's tree, taken L at a time.
__attribute__((always_inline)) inline void writeSums(const TileGaussian<float>& g, const GradSums& s, float* sl) {
  constexpr int kSums = 9;
  constexpr int kPadded = (kSums + L - 1) / L * L;
  vf v[kPadded] = {s.e, s.x, s.y, s.xx, s.xy, s.yy, s.c0, s.c1, s.c2};
  alignas(64) float sum[kPadded];
  for (int k = 0; k < kPadded; k += L) store(sum + k, transposeSums(v + k));
  const float e = sum[0], ex = sum[1], ey = sum[2], exx = sum[3], exy = sum[4], eyy = sum[5];
  sl[0] = e;
  sl[1] = g.o * (g.a * ex + g.b * ey);
  sl[2] = g.o * (g.b * ex + g.c * ey);
  sl[3] = -0.5f * g.o * exx;
  sl[4] = -g.o * exy;
  sl[5] = -0.5f * g.o * eyy;
  sl[6] = sum[6];
  sl[7] = sum[7];
  sl[8] = sum[8];
}

// A Gaussian's per-block constants of backStep.
struct BackwardColour {
  vf col0, col1, col2, jv;
  BackwardColour(const TileGaussian<float>& g, std::uint32_t jj)
      : col0(vs(g.col[0])), col1(vs(g.col[1])), col2(vs(g.col[2])), jv(vs(static_cast<float>(jj))) {}
};

// The slots of tile entries [from, to), which no walk reaches (the kernels write every
// slot, so callers need no cleared buffer).
inline void zeroSlots(float* slots, int from, int to) {
  if (from < to)
    std::memset(&slots[static_cast<std::size_t>(from) * kSlot], 0,
                sizeof(float) * kSlot * static_cast<std::size_t>(to - from));
}

inline GradSums zeroSums() {
  const vf z = vs(0.0f);
  return GradSums{z, z, z, z, z, z, z, z, z};
}

// The back-to-front walk (the scalar walkBack of raster_stages.h, per lane), Gaussian by
// Gaussian. Entries beyond the longest walk get zero slots, so the caller needs no
// cleared buffer.
template <bool kBg>
void backwardTileImpl(const TileGaussian<float>* q, int nq, int x0, int y0, int x1, int y1, const float bg[3],
                      const BackwardIn& in, float* slots) {
  BackwardState B;
  B.init(x0, y0, x1 - x0, y1 - y0, bg, in);
  zeroSlots(slots, static_cast<int>(B.jmax), nq);
  for (std::uint32_t jj = B.jmax; jj-- > 0;) {
    const TileGaussian<float>& g = q[jj];
    const BackwardColour bc(g, jj);
    GradSums s = zeroSums();
    forEachBlock(g, x0, y0, x1, y1, [&](int blk, const Lanes& Ln, vf dy) {
      vf e, wcol;
      backStep<kBg>(B.b[blk], Ln, bc.jv, bc.col0, bc.col1, bc.col2, e, wcol);
      addMoments(s, e, Ln.dx, dy);
      addColours(s, wcol, B.b[blk]);
    });
    writeSums(g, s, &slots[static_cast<std::size_t>(jj) * kSlot]);
  }
}

inline void backwardTile(const TileGaussian<float>* q, int nq, int x0, int y0, int x1, int y1, const float bg[3],
                         const BackwardIn& in, float* slots) {
  if (nq == 0) return;
  if (bg[0] != 0.0f || bg[1] != 0.0f || bg[2] != 0.0f)
    backwardTileImpl<true>(q, nq, x0, y0, x1, y1, bg, in, slots);
  else
    backwardTileImpl<false>(q, nq, x0, y0, x1, y1, bg, in, slots);
}

// FisherRF's squared-gradient pass (FisherMoment in raster_kernels.h): the backward walk
// for the fixed objective C_r + C_g + C_b, accumulating moments instead of gradients.
// Kept apart from the backward kernel: its weights are all 1, so the three colour
// accumulators collapse into one (sum_c (col_c - acc_c) = sum col - sum acc, and each
// acc_c is updated linearly), and the background term is the same for every pixel.
template <bool kBg>
void fisherTileImpl(const TileGaussian<float>* q, int nq, int x0, int y0, int x1, int y1, float bg_sum,
                    const FisherIn& in, float* slots) {
  constexpr int P = kTile * kTile;
  constexpr int M = kFisherSlot;
  const int w = x1 - x0, h = y1 - y0;
  alignas(64) float Tr[P], finalT[P], walked[P], acc[P];
  // The two-pass form's scratch: per block of the current Gaussian e and wc, and the
  // block's storage index (unused by the one-pass form).
  [[maybe_unused]] alignas(64) float eb[P], wb[P];
  [[maybe_unused]] int block[P / L];
  [[maybe_unused]] const vf lane_x = laneColCentres(), lane_y = laneRowCentres();
  std::uint32_t jmax = 0;
  for (int k = 0; k < P; ++k) {
    const int r = blockRow(k), c = blockCol(k);
    const bool inside = c < w && r < h;
    const std::size_t pix = inside ? static_cast<std::size_t>(y0 + r) * in.W + (x0 + c) : 0;
    Tr[k] = finalT[k] = inside ? in.final_T[pix] : 1.0f;
    const std::uint32_t nw = inside ? in.n_walked[pix] : 0;
    walked[k] = static_cast<float>(nw);
    jmax = nw > jmax ? nw : jmax;
    acc[k] = 0.0f;
  }
  // Entries no pixel walks have no information; their slots are written here all the
  // same, so that the caller needs no cleared buffer.
  if (static_cast<int>(jmax) < nq)
    std::memset(&slots[static_cast<std::size_t>(jmax) * M], 0, sizeof(float) * M * (nq - jmax));
  const vf zero = vs(0.0f), one = vs(1.0f), bgs = vs(bg_sum);
  // The walk's step at block k (pixel storage index): updates the block's transmittance
  // and colour sum, and gives e = G dL/dalpha (0 where alpha is clamped or the entry does
  // not touch the pixel) and the colour weight wc = alpha T (0 where not valid).
  auto step = [&](int k, const Lanes& Ln, vf jv, vf colsum, vf& e, vf& wc) __attribute__((always_inline)) {
    const vf alpha = Ln.alpha;
    const vi valid = (jv < load(walked + k)) & Ln.touches;
    const vf a_eff = maskOr0(valid, alpha);
    const vf t = load(Tr + k) / (one - a_eff);  // transmittance in front of jj
    store(Tr + k, t);
    const vf a = load(acc + k), d = colsum - a;
    vf dLda = d * t;
    if constexpr (kBg) dLda = dLda - load(finalT + k) / (one - alpha) * bgs;
    store(acc + k, fma(a_eff, d, a));
    const vi gm = valid & (Ln.oG < vs(kMaxA));
    e = maskOr0(gm, Ln.G * dLda);
    wc = a_eff * t;
  };
  for (std::uint32_t jj = jmax; jj-- > 0;) {
    const TileGaussian<float>& g = q[jj];
    const vf jv = vs(static_cast<float>(jj));
    const vf colsum = vs(g.col[0] + g.col[1] + g.col[2]);
    // The 19 moment sums, lanes not yet added, padded to whole vectors.
    constexpr int kPadded = (M + L - 1) / L * L;
    vf m[kPadded];
    for (int k = M; k < kPadded; ++k) m[k] = zero;
    if constexpr (KernelIsa::kFisherOnePass) {
      // One pass: the walk's e and wc go straight into the 19 accumulators, each summed
      // with the same operations, in the same block order, as in the three passes below.
      vf e00 = zero, e20 = zero, e11 = zero, e02 = zero, f10 = zero, f01 = zero, ww = zero;
      vf e30 = zero, e21 = zero, e12 = zero, e03 = zero, f20 = zero, f11 = zero, f02 = zero;
      vf e40 = zero, e31 = zero, e22 = zero, e13 = zero, e04 = zero;
      forEachBlock(g, x0, y0, x1, y1, [&](int blk, const Lanes& Ln, vf dy) {
        vf e, wc;
        step(blk * L, Ln, jv, colsum, e, wc);
        const vf dx = Ln.dx;
        const vf e2 = e * e, ew = e * wc;
        const vf xx = dx * dx, xy = dx * dy, yy = dy * dy;
        const vf e2xx = e2 * xx, e2yy = e2 * yy;
        e00 += e2;
        e20 += e2xx;
        e11 = fma(e2 * dx, dy, e11);
        e02 += e2yy;
        f10 = fma(ew, dx, f10);
        f01 = fma(ew, dy, f01);
        ww = fma(wc, wc, ww);
        e30 = fma(e2xx, dx, e30);
        e21 = fma(e2xx, dy, e21);
        e12 = fma(e2yy, dx, e12);
        e03 = fma(e2yy, dy, e03);
        f20 = fma(ew, xx, f20);
        f11 = fma(ew, xy, f11);
        f02 = fma(ew, yy, f02);
        e40 = fma(e2xx, xx, e40);
        e31 = fma(e2xx, xy, e31);
        e22 = fma(e2xx, yy, e22);
        e13 = fma(e2yy, xy, e13);
        e04 = fma(e2yy, yy, e04);
      });
      m[kE00] = e00, m[kE20] = e20, m[kE11] = e11, m[kE02] = e02, m[kF10] = f10, m[kF01] = f01, m[kW] = ww;
      m[kE30] = e30, m[kE21] = e21, m[kE12] = e12, m[kE03] = e03, m[kF20] = f20, m[kF11] = f11, m[kF02] = f02;
      m[kE40] = e40, m[kE31] = e31, m[kE22] = e22, m[kE13] = e13, m[kE04] = e04;
    } else {
      const vf mx = vs(g.mx), my = vs(g.my);
      // Two passes over the Gaussian's blocks. The walk keeps each block's e and wc in
      // scratch; the moments are then summed in three groups small enough to stay in
      // registers (nineteen accumulators spilled to the stack made every block pay
      // nineteen stores, which bound the kernel).
      int nb = 0;
      forEachBlock(g, x0, y0, x1, y1, [&](int blk, const Lanes& Ln, vf) {
        vf e, wc;
        step(blk * L, Ln, jv, colsum, e, wc);
        store(eb + nb * L, e);
        store(wb + nb * L, wc);
        block[nb++] = blk * L;
      });
      // The offsets of block n's pixels, as the walk computed them.
      auto offsets = [&](int n, vf& dx, vf& dy) {
        const int b = block[n] / L;
        dx = (vs(static_cast<float>(x0 + b % kBX * kBW)) + lane_x) - mx;
        dy = (vs(static_cast<float>(y0 + b / kBX * kBH)) + lane_y) - my;
      };
      {
        vf e00 = zero, e20 = zero, e11 = zero, e02 = zero, f10 = zero, f01 = zero, ww = zero;
        for (int n = 0; n < nb; ++n) {
          vf dx, dy;
          offsets(n, dx, dy);
          const vf e = load(eb + n * L), wc = load(wb + n * L);
          const vf e2 = e * e, ew = e * wc;
          e00 += e2;
          e20 += e2 * (dx * dx);
          e11 = fma(e2 * dx, dy, e11);
          e02 += e2 * (dy * dy);
          f10 = fma(ew, dx, f10);
          f01 = fma(ew, dy, f01);
          ww = fma(wc, wc, ww);
        }
        m[kE00] = e00, m[kE20] = e20, m[kE11] = e11, m[kE02] = e02, m[kF10] = f10, m[kF01] = f01, m[kW] = ww;
      }
      {
        vf e30 = zero, e21 = zero, e12 = zero, e03 = zero, f20 = zero, f11 = zero, f02 = zero;
        for (int n = 0; n < nb; ++n) {
          vf dx, dy;
          offsets(n, dx, dy);
          const vf e = load(eb + n * L), wc = load(wb + n * L);
          const vf e2 = e * e, ew = e * wc;
          const vf e2xx = e2 * (dx * dx), e2yy = e2 * (dy * dy);
          e30 = fma(e2xx, dx, e30);
          e21 = fma(e2xx, dy, e21);
          e12 = fma(e2yy, dx, e12);
          e03 = fma(e2yy, dy, e03);
          f20 = fma(ew, dx * dx, f20);
          f11 = fma(ew, dx * dy, f11);
          f02 = fma(ew, dy * dy, f02);
        }
        m[kE30] = e30, m[kE21] = e21, m[kE12] = e12, m[kE03] = e03, m[kF20] = f20, m[kF11] = f11, m[kF02] = f02;
      }
      {
        vf e40 = zero, e31 = zero, e22 = zero, e13 = zero, e04 = zero;
        for (int n = 0; n < nb; ++n) {
          vf dx, dy;
          offsets(n, dx, dy);
          const vf e = load(eb + n * L);
          const vf e2 = e * e, xx = dx * dx, xy = dx * dy, yy = dy * dy;
          const vf e2xx = e2 * xx, e2yy = e2 * yy;
          e40 = fma(e2xx, xx, e40);
          e31 = fma(e2xx, xy, e31);
          e22 = fma(e2xx, yy, e22);
          e13 = fma(e2yy, xy, e13);
          e04 = fma(e2yy, yy, e04);
        }
        m[kE40] = e40, m[kE31] = e31, m[kE22] = e22, m[kE13] = e13, m[kE04] = e04;
      }
    }
    // Straight into the slot, whole vectors and then the last few lanes. (Through a stack
    // array and memcpy, the copy's wide loads each spanned two of the vector stores just
    // made, which a store cannot forward: the load waited for both to reach the cache,
    // about 39 % of this kernel's samples on AVX-512VL in `bench fisher`.)
    float* sl = &slots[static_cast<std::size_t>(jj) * M];
    int k = 0;
    for (; k + L <= M; k += L) store(sl + k, transposeSums(m + k));
    if (k < M) {
      const vf last = transposeSums(m + k);
      for (int i = 0; k + i < M; ++i) sl[k + i] = last[i];
    }
  }
}

inline void fisherTile(const TileGaussian<float>* q, int nq, int x0, int y0, int x1, int y1, const float bg[3],
                       const FisherIn& in, float* slots) {
  if (nq == 0) return;
  const float bg_sum = bg[0] + bg[1] + bg[2];
  if (bg_sum != 0.0f)
    fisherTileImpl<true>(q, nq, x0, y0, x1, y1, bg_sum, in, slots);
  else
    fisherTileImpl<false>(q, nq, x0, y0, x1, y1, bg_sum, in, slots);
}

}  // namespace
}  // namespace saresgs::raster_kernels
