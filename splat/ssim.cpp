// The fused SSIM (+ L1) kernel (splat/ssim.h).
#include "splat/ssim.h"
#include "geometry/float_env.h"
#include "splat/kept_buffers.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <vector>

// Notation, per channel and pixel p (G is the normalised 11x11 Gaussian, zero padding):
//   mx = G*x, my = G*y, md = G*(x - y), pxy = G*(x y), dd = G*((x - y)^2)
//   cxy = pxy - mx my (covariance), vd = dd - md^2 (variance of x - y)
//   A1 = 2 mx my + C1,  B1 = mx^2 + my^2 + C1 = A1 + md^2
//   A2 = 2 cxy + C2,    B2 = vx + vy + C2     = A2 + vd
//   S  = A1 A2 / (B1 B2),  1 - S = (A1 vd + md^2 B2) / (B1 B2)
// This is the usual SSIM (md = mx - my and vx + vy = vd + 2 cxy), arranged so that float
// arithmetic stays accurate. vx + vy computed as G*(x^2) - mx^2 + G*(y^2) - my^2 loses
// most of a float's digits where the image is flat and bright; md and vd instead come from
// the filtered difference x - y, so they are small, and accurate, exactly where render
// and target agree, and 1 - S is formed as a ratio of non-negative terms (no
// 1 - 0.9999 cancellation). The covariance is formed from values shifted by c = 0.5,
// x' = x - c and y' = y - c, which halves their size: with W = G*1 (1 except within five
// pixels of a border, where the zero padding cuts the window),
//   mx = G*x' + c W,  my = G*y' + c W,
//   cxy = (G*(x'y') - G*x' G*y') + c (1 - W) (G*x' + G*y') + c^2 W (1 - W).
// Against a double evaluation the mean of 1 - S then agrees to ~3e-8 relative on noisy,
// offset and flat-background test images and to <= 5e-7 where render and target are flat
// and far apart (vd = G*(d^2) - md^2 is then a difference of two values near d^2);
// gradients agree to ~1e-5 of the largest value. Render == target gives md = vd = 0 bit
// for bit, hence S = 1 and a zero gradient exactly.
//
// The render x enters through mx, md, pxy and dd; as md = mx - my, S is a function of
// (mx, my, pxy, dd) and, with inv = 1 / (B1 B2) and my held fixed,
//   dS/dmx  = 2 inv [ (A2 - A1) (mx (1 - S) - md) - mx S (vd - md^2) ]
//   dS/dpxy = 2 A1 vd B1 inv^2                         (= 2 (A1 - S B1) inv)
//   dS/ddd  = -S B1 inv                                (= -S / B2)
// and, by the chain rule through the filter, for a render value q
//   d(sum_p S_p)/dx_q = (G^T * dS/dmx)_q + y_q (G^T * dS/dpxy)_q + 2 (x_q - y_q) (G^T * dS/ddd)_q,
// evaluated as (G^T * (dS/dmx + c dS/dpxy))_q + y'_q (G^T * dS/dpxy)_q + ... (the same
// sum, with smaller terms).
// G with zero padding is out_p = sum_{q inside} g(p - q) in_q; its adjoint is
// in_q = sum_{p inside} g(p - q) out_p, the same filter because g is symmetric.
//
// Layout: images are interleaved, so a row is one contiguous run of W = w * channels
// floats; the horizontal filter is an 11-tap filter with stride `channels` over that run,
// the vertical one combines 11 whole rows. Both are plain float loops that GCC vectorises
// (SSE2 is enough; AVX2 or AVX-512 is used at run time where present, with identical results). The
// 2-D window is the outer product of the 1-D window normalised in double (as before),
// rounded to float. Work is split into fixed blocks of kBlockRows rows; each row is
// computed by the same operations whichever block or thread handles it, and per-row sums
// (float runs of 4, then double) are added in row order, so results are bit-identical
// for any thread count.
//
// Per block, forward: the five filter inputs (x', y', x - y, x'y', (x - y)^2) of each
// input row go into a ring; groups of four output rows are filtered vertically from it,
// then horizontally; the SSIM terms give 1 - S and, with the gradient, the three scaled
// partials, written to full-size maps. Backward (after all blocks): the partial maps are
// filtered the same way and combined per value.

// Runtime AVX2 / AVX-512 dispatch needs GCC-style target attributes and __builtin_cpu_supports.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__AVX2__)
#define SARESGS_SSIM_AVX2 1
#else
#define SARESGS_SSIM_AVX2 0
#endif

namespace saresgs {

namespace {

constexpr int kRadius = 5;
constexpr int kTaps = 2 * kRadius + 1;
constexpr float kC1 = static_cast<float>(0.01 * 0.01);
constexpr float kC2 = static_cast<float>(0.03 * 0.03);
constexpr float kShift = 0.5f;  // c: x' = x - c, y' = y - c
constexpr int kBlockRows = 32;

// g[0] is the centre tap, g[k] the taps at -k and +k.
const std::array<float, kRadius + 1>& window() {
  static const std::array<float, kRadius + 1> g = [] {
    std::array<double, kTaps> k{};
    double sum = 0;
    for (int i = 0; i < kTaps; ++i) {
      const double d = i - kRadius;
      k[i] = std::exp(-d * d / (2.0 * 1.5 * 1.5));
      sum += k[i];
    }
    std::array<float, kRadius + 1> out{};
    for (int i = 0; i <= kRadius; ++i) out[i] = static_cast<float>(k[kRadius + i] / sum);
    return out;
  }();
  return g;
}

// Sum of the (float) taps that fall inside [0, n) around position p: the filter of an
// all-ones image along one axis. In double; the 2-D W is the product of two of these.
double insideWeight(int p, int n) {
  const auto& g = window();
  double s = 0;
  for (int k = -kRadius; k <= kRadius; ++k)
    if (p + k >= 0 && p + k < n) s += g[k < 0 ? -k : k];
  return s;
}

// The loops below are written once, as always-inline bodies, and compiled three times (see
// Kernels): for the baseline target (SSE2 on x86-64) and, where the CPU has them, for AVX2
// and for AVX-512. All perform the same IEEE operations in the same order on each value
// (nothing is reassociated, and no multiply-add is fused: -ffp-contract=off in
// splat/CMakeLists.txt, as GCC fuses them by default in C++ wherever the target has FMA),
// so they give identical bits; AVX2 and AVX-512 only do 8 or 16 values per instruction
// instead of 4.
#define SARESGS_KERNEL inline __attribute__((always_inline))

using Taps = std::array<float, kRadius + 1>;

// out[i] = sum_k g_|k| rows[kRadius + k][i]; rows outside the image point at a zero row.
// Summed from the outer (small) taps inwards.
SARESGS_KERNEL void verticalBody(const float* const* rows, float* __restrict out, std::size_t n, const Taps& g) {
  const float* __restrict u5 = rows[0];
  const float* __restrict u4 = rows[1];
  const float* __restrict u3 = rows[2];
  const float* __restrict u2 = rows[3];
  const float* __restrict u1 = rows[4];
  const float* __restrict c0 = rows[5];
  const float* __restrict d1 = rows[6];
  const float* __restrict d2 = rows[7];
  const float* __restrict d3 = rows[8];
  const float* __restrict d4 = rows[9];
  const float* __restrict d5 = rows[10];
  const float g0 = g[0], g1 = g[1], g2 = g[2], g3 = g[3], g4 = g[4], g5 = g[5];
  for (std::size_t i = 0; i < n; ++i)
    out[i] = g5 * (u5[i] + d5[i]) + g4 * (u4[i] + d4[i]) + g3 * (u3[i] + d3[i]) + g2 * (u2[i] + d2[i]) +
             g1 * (u1[i] + d1[i]) + g0 * c0[i];
}

// verticalBody for four consecutive output rows (rows[0..13] = input rows r-5 .. r+8):
// each output is the same expression as there, so the same bits, but every input row is
// loaded once for four outputs instead of four times.
SARESGS_KERNEL void vertical4Body(const float* const* rows, float* __restrict out0, float* __restrict out1,
                                  float* __restrict out2, float* __restrict out3, std::size_t n, const Taps& g) {
  const float* __restrict r0 = rows[0];
  const float* __restrict r1 = rows[1];
  const float* __restrict r2 = rows[2];
  const float* __restrict r3 = rows[3];
  const float* __restrict r4 = rows[4];
  const float* __restrict r5 = rows[5];
  const float* __restrict r6 = rows[6];
  const float* __restrict r7 = rows[7];
  const float* __restrict r8 = rows[8];
  const float* __restrict r9 = rows[9];
  const float* __restrict r10 = rows[10];
  const float* __restrict r11 = rows[11];
  const float* __restrict r12 = rows[12];
  const float* __restrict r13 = rows[13];
  const float g0 = g[0], g1 = g[1], g2 = g[2], g3 = g[3], g4 = g[4], g5 = g[5];
  for (std::size_t i = 0; i < n; ++i) {
    const float a0 = r0[i], a1 = r1[i], a2 = r2[i], a3 = r3[i], a4 = r4[i], a5 = r5[i];
    const float a6 = r6[i], a7 = r7[i], a8 = r8[i], a9 = r9[i], a10 = r10[i], a11 = r11[i];
    const float a12 = r12[i], a13 = r13[i];
    out0[i] = g5 * (a0 + a10) + g4 * (a1 + a9) + g3 * (a2 + a8) + g2 * (a3 + a7) + g1 * (a4 + a6) + g0 * a5;
    out1[i] = g5 * (a1 + a11) + g4 * (a2 + a10) + g3 * (a3 + a9) + g2 * (a4 + a8) + g1 * (a5 + a7) + g0 * a6;
    out2[i] = g5 * (a2 + a12) + g4 * (a3 + a11) + g3 * (a4 + a10) + g2 * (a5 + a9) + g1 * (a6 + a8) + g0 * a7;
    out3[i] = g5 * (a3 + a13) + g4 * (a4 + a12) + g3 * (a5 + a11) + g2 * (a6 + a10) + g1 * (a7 + a9) + g0 * a8;
  }
}

// out[i] = sum_k g_|k| t[i + k * stride]; t has kRadius * stride zeros before and after.
SARESGS_KERNEL void horizontalBody(const float* __restrict t, float* __restrict out, std::size_t n, std::ptrdiff_t s,
                                   const Taps& g) {
  const float g0 = g[0], g1 = g[1], g2 = g[2], g3 = g[3], g4 = g[4], g5 = g[5];
  for (std::size_t i = 0; i < n; ++i) {
    const float* c = t + i;
    out[i] = g5 * (c[-5 * s] + c[5 * s]) + g4 * (c[-4 * s] + c[4 * s]) + g3 * (c[-3 * s] + c[3 * s]) +
             g2 * (c[-2 * s] + c[2 * s]) + g1 * (c[-s] + c[s]) + g0 * c[0];
  }
}

// Inputs of the five filters for one row: x', y', x - y, x' y', (x - y)^2. The difference
// is taken from the unshifted values, so it is exactly zero where render == target.
SARESGS_KERNEL void productsBody(const float* __restrict x, const float* __restrict y, float* __restrict xs,
                                 float* __restrict ys, float* __restrict d, float* __restrict p, float* __restrict q,
                                 std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    const float a = x[i] - kShift, b = y[i] - kShift, e = x[i] - y[i];
    xs[i] = a;
    ys[i] = b;
    d[i] = e;
    p[i] = a * b;
    q[i] = e * e;
  }
}

// The filtered maps of one row and the window weight W = G*1 at each of its values.
struct Filtered {
  const float* mxs;  // G*x'
  const float* mys;  // G*y'
  const float* md;   // G*(x - y)
  const float* pxy;  // G*(x' y')
  const float* dd;   // G*((x - y)^2)
  const float* wx;   // horizontal part of W (per value of the row)
  float wy;          // vertical part of W (this row)
};

// The SSIM terms at one value (notation at the top of the file), from the filtered
// values and W = G*1 there. Swapping x and y swaps mx and my and negates md, which leaves
// every quantity here unchanged bit for bit.
struct Terms {
  float mx, md, md2, A1, B1, A2, B2, vd, inv, om;  // om = 1 - S
};

SARESGS_KERNEL Terms ssimTerms(float mxs, float mys, float md, float pxy, float dd, float wgt) {
  Terms t;
  const float out = 1.0f - wgt;  // 1 - W: zero away from the borders
  t.mx = mxs + kShift * wgt;
  const float my = mys + kShift * wgt;
  t.md = md;
  t.md2 = md * md;
  const float cxy = (pxy - mxs * mys) + (kShift * out * (mxs + mys) + kShift * kShift * wgt * out);
  t.A1 = 2.0f * (t.mx * my) + kC1;
  t.B1 = t.A1 + t.md2;
  t.A2 = 2.0f * cxy + kC2;
  t.vd = dd - t.md2;
  t.B2 = t.A2 + t.vd;
  t.inv = 1.0f / (t.B1 * t.B2);
  t.om = (t.A1 * t.vd + t.md2 * t.B2) * t.inv;
  return t;
}

SARESGS_KERNEL void pointBody(const Filtered& f, float* __restrict om, std::size_t n) {
  const float* __restrict mxs = f.mxs;
  const float* __restrict mys = f.mys;
  const float* __restrict md = f.md;
  const float* __restrict pxy = f.pxy;
  const float* __restrict dd = f.dd;
  const float* __restrict wx = f.wx;
  const float wy = f.wy;
  for (std::size_t i = 0; i < n; ++i) om[i] = ssimTerms(mxs[i], mys[i], md[i], pxy[i], dd[i], wy * wx[i]).om;
}

// As pointBody (the same om), plus the partials with respect to the filtered render
// quantities, times `scale`: a = dS/dmx' (= dS/dmx + c dS/dpxy), b = dS/ddd, c = dS/dpxy'.
SARESGS_KERNEL void pointGradBody(const Filtered& f, float* __restrict om, float* __restrict a, float* __restrict b,
                                  float* __restrict c, std::size_t n, float scale) {
  const float* __restrict mxs = f.mxs;
  const float* __restrict mys = f.mys;
  const float* __restrict md = f.md;
  const float* __restrict pxy = f.pxy;
  const float* __restrict dd = f.dd;
  const float* __restrict wx = f.wx;
  const float wy = f.wy;
  for (std::size_t i = 0; i < n; ++i) {
    const Terms t = ssimTerms(mxs[i], mys[i], md[i], pxy[i], dd[i], wy * wx[i]);
    const float S = 1.0f - t.om;
    om[i] = t.om;
    const float dmx = 2.0f * t.inv * ((t.A2 - t.A1) * (t.mx * t.om - t.md) - t.mx * S * (t.vd - t.md2));
    const float dpxy = 2.0f * t.A1 * t.B1 * t.vd * t.inv * t.inv;
    a[i] = scale * (dmx + kShift * dpxy);
    b[i] = scale * (-(S * t.B1) * t.inv);
    c[i] = scale * dpxy;
  }
}

// The chain rule for one row: grad = l1 + G*a + y' G*c + 2 (x - y) G*b.
SARESGS_KERNEL void combineBody(const float* __restrict x, const float* __restrict y, const float* __restrict ga,
                                const float* __restrict gb, const float* __restrict gc, float* __restrict grad,
                                std::size_t n, float l1_scale) {
  for (std::size_t i = 0; i < n; ++i) {
    const float d = x[i] - y[i];
    const float l1 = d > 0 ? l1_scale : (d < 0 ? -l1_scale : 0.0f);
    grad[i] = l1 + (ga[i] + ((y[i] - kShift) * gc[i] + 2.0f * d * gb[i]));
  }
}

// The L1 part alone (lambda == 0): l1_scale * sign(x - y), from the row of differences.
SARESGS_KERNEL void signBody(const float* __restrict d, float* __restrict grad, std::size_t n, float l1_scale) {
  for (std::size_t i = 0; i < n; ++i) grad[i] = d[i] > 0 ? l1_scale : (d[i] < 0 ? -l1_scale : 0.0f);
}

struct Kernels {
  void (*vertical)(const float* const*, float*, std::size_t, const Taps&);
  void (*vertical4)(const float* const*, float*, float*, float*, float*, std::size_t, const Taps&);
  void (*horizontal)(const float*, float*, std::size_t, std::ptrdiff_t, const Taps&);
  void (*products)(const float*, const float*, float*, float*, float*, float*, float*, std::size_t);
  void (*point)(const Filtered&, float*, std::size_t);
  void (*pointGrad)(const Filtered&, float*, float*, float*, float*, std::size_t, float);
  void (*combine)(const float*, const float*, const float*, const float*, const float*, float*, std::size_t, float);
  void (*sign)(const float*, float*, std::size_t, float);
};

// Instantiates the bodies for one target; ATTR is empty (baseline) or a target attribute.
#define SARESGS_KERNEL_SET(NAME, ATTR)                                                                                 \
  ATTR void vertical##NAME(const float* const* rows, float* out, std::size_t n, const Taps& g) {                       \
    verticalBody(rows, out, n, g);                                                                                     \
  }                                                                                                                    \
  ATTR void vertical4##NAME(const float* const* rows, float* out0, float* out1, float* out2, float* out3,              \
                            std::size_t n, const Taps& g) {                                                            \
    vertical4Body(rows, out0, out1, out2, out3, n, g);                                                                 \
  }                                                                                                                    \
  ATTR void horizontal##NAME(const float* t, float* out, std::size_t n, std::ptrdiff_t s, const Taps& g) {             \
    horizontalBody(t, out, n, s, g);                                                                                   \
  }                                                                                                                    \
  ATTR void products##NAME(const float* x, const float* y, float* xs, float* ys, float* d, float* p, float* q,         \
                           std::size_t n) {                                                                            \
    productsBody(x, y, xs, ys, d, p, q, n);                                                                            \
  }                                                                                                                    \
  ATTR void point##NAME(const Filtered& f, float* om, std::size_t n) { pointBody(f, om, n); }                          \
  ATTR void pointGrad##NAME(const Filtered& f, float* om, float* a, float* b, float* c, std::size_t n, float scale) {  \
    pointGradBody(f, om, a, b, c, n, scale);                                                                           \
  }                                                                                                                    \
  ATTR void combine##NAME(const float* x, const float* y, const float* ga, const float* gb, const float* gc,           \
                          float* grad, std::size_t n, float l1_scale) {                                                \
    combineBody(x, y, ga, gb, gc, grad, n, l1_scale);                                                                  \
  }                                                                                                                    \
  ATTR void sign##NAME(const float* d, float* grad, std::size_t n, float l1_scale) { signBody(d, grad, n, l1_scale); } \
  constexpr Kernels kKernels##NAME = {vertical##NAME, vertical4##NAME, horizontal##NAME, products##NAME,               \
                                      point##NAME,    pointGrad##NAME, combine##NAME,    sign##NAME};

SARESGS_KERNEL_SET(Base, )
#if SARESGS_SSIM_AVX2
SARESGS_KERNEL_SET(Avx2, __attribute__((target("avx2"))))
// 16 floats per instruction: on the AMD EPYC VM the loss stage of `bench train --residual`
// (room360 256x192, 3 rounds alternated with the AVX2 build) took 0.89-0.91 ms against
// 1.06-1.07. 256-bit AVX-512 code, for its 32 registers only, gained less in a first,
// rougher comparison.
SARESGS_KERNEL_SET(Avx512, __attribute__((target("avx512f,avx512vl,prefer-vector-width=512"))))
#endif

std::atomic<int> g_widest{static_cast<int>(SsimIsa::kAvx512)};

const Kernels& kernels() {
#if SARESGS_SSIM_AVX2
  const SsimIsa isa = std::min(ssimBestIsa(), static_cast<SsimIsa>(g_widest.load(std::memory_order_relaxed)));
  if (isa == SsimIsa::kAvx512) return kKernelsAvx512;
  if (isa == SsimIsa::kAvx2) return kKernelsAvx2;
#endif
  return kKernelsBase;
}

typedef float v4f __attribute__((vector_size(16)));
typedef double v2d __attribute__((vector_size(16)));

v4f load4(const float* p) {
  v4f v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// Sum of n floats (of |floats| when Abs) in a fixed order: runs of 4 consecutive values
// per lane are added in float, then each run total in double.
template <bool Abs>
double sumChunked(const float* p, std::size_t n) {
  v2d a0 = {0, 0}, a1 = {0, 0};
  std::size_t i = 0;
  for (; i + 16 <= n; i += 16) {
    v4f u0 = load4(p + i), u1 = load4(p + i + 4), u2 = load4(p + i + 8), u3 = load4(p + i + 12);
    if constexpr (Abs) {
      u0 = u0 < 0 ? -u0 : u0;
      u1 = u1 < 0 ? -u1 : u1;
      u2 = u2 < 0 ? -u2 : u2;
      u3 = u3 < 0 ? -u3 : u3;
    }
    const v4f t = (u0 + u1) + (u2 + u3);
    a0 += v2d{t[0], t[1]};
    a1 += v2d{t[2], t[3]};
  }
  const v2d a = a0 + a1;
  double s = a[0] + a[1];
  for (; i < n; ++i) s += Abs ? std::abs(p[i]) : p[i];
  return s;
}

struct Job {
  const float* x;
  const float* y;
  int h;
  int channels;
  std::size_t W;    // floats per row
  std::size_t pad;  // kRadius * channels
  float* grad;      // null: no gradient
  float l1_scale;
  float ssim_scale;
  bool ssim_grad;  // grad && ssim_scale != 0
  float* da;       // scaled partial maps (h rows of dstride floats) when ssim_grad,
  float* db;       // see pointGradBody
  float* dc;
  std::size_t dstride;
  const Kernels* k;    // the kernel set for this CPU
  const float* zeros;  // W zeros
  const float* wx;     // horizontal window weight per value of a row
  const float* wy;     // vertical window weight per row
  double* row_om;      // per-row sums of 1 - S
  double* row_l1;      // per-row sums of |x - y|
};

// What one ssimL1 call needs beside its blocks' scratch (see ssimL1).
struct CallBuffers {
  std::vector<float> zeros, wx, wy, partials;
  std::vector<double> row_om, row_l1;
};

// Per-thread scratch, kept between calls (the loss runs every training iteration). A
// block never waits on other TBB work, so no two blocks share a thread's scratch at once.
std::vector<float>& scratch(std::size_t n) {
  thread_local std::vector<float> buf;
  if (buf.size() < n) buf.assign(n, 0.0f);
  return buf;
}

// Rows are processed in groups of four (single rows at the end of a block): the vertical
// filter then reads each input row once for four outputs. Every output value is the
// same expression either way, so a row's values do not depend on its group or block.
constexpr int kGroup = 4;
constexpr int kRing = kTaps + kGroup - 1;  // input rows one group reads

struct RowGroup {
  int r;      // first output row
  int count;  // 1 or kGroup rows
};

RowGroup groupAt(int r, int r1) { return {r, r1 - r >= kGroup ? kGroup : 1}; }

// Row stride for scratch rows of W floats: whole cache lines, and never a multiple of
// 4 KiB, so that the rows one vertical pass reads do not alias in the L1 cache.
std::size_t rowStride(std::size_t W) {
  std::size_t s = (W + 15) / 16 * 16;
  if (s % 1024 == 0) s += 16;
  return s;
}

// Filters one map for the output rows of group `p`: vertical pass into the zero-padded
// rows v[t], then the horizontal pass into out[t]. rowOf(j) gives input row j of the map
// for 0 <= j < h.
template <typename RowOf>
void filterMap(const Job& J, RowOf&& rowOf, RowGroup p, float* const* v, float* const* out) {
  const auto& g = window();
  const float* rows[kRing];
  for (int k = 0; k < kTaps + p.count - 1; ++k) {
    const int j = p.r - kRadius + k;
    rows[k] = (j >= 0 && j < J.h) ? rowOf(j) : J.zeros;
  }
  const std::size_t P = J.pad, W = J.W;
  if (p.count == kGroup)
    J.k->vertical4(rows, v[0] + P, v[1] + P, v[2] + P, v[3] + P, W, g);
  else
    J.k->vertical(rows, v[0] + P, W, g);
  for (int t = 0; t < p.count; ++t) J.k->horizontal(v[t] + P, out[t], W, J.channels, g);
}

// kGroup zero-padded rows for the vertical pass's output, from `at`; returns the end.
float* paddedRows(const Job& J, float* at, float** v) {
  const std::size_t PW = rowStride(J.W + 2 * J.pad);
  for (int t = 0; t < kGroup; ++t) {
    v[t] = at + t * PW;
    std::fill(v[t], v[t] + J.pad, 0.0f);
    std::fill(v[t] + J.pad + J.W, v[t] + PW, 0.0f);
  }
  return at + kGroup * PW;
}

// Forward over rows [r0, r1): SSIM map and L1 per row, and the scaled SSIM partials.
// The five filter inputs are computed once per input row into a ring of kRing rows.
void forwardBlock(const Job& J, int r0, int r1) {
  constexpr int kMaps = 5;
  const std::size_t W = J.W, S = rowStride(W), ring = kRing * S;
  std::vector<float>& buf = scratch(kMaps * ring + kGroup * rowStride(W + 2 * J.pad) + (kGroup * kMaps + 1) * S);
  float* prod = buf.data();  // kMaps rings; input row j in slot j % kRing
  float* v[kGroup];
  float* hrow = paddedRows(J, prod + kMaps * ring, v);  // kGroup x kMaps filtered rows
  float* om = hrow + kGroup * kMaps * S;
  auto slot = [&](int m, int j) { return prod + m * ring + static_cast<std::size_t>(j % kRing) * S; };
  auto fillRow = [&](int j) {
    if (j >= J.h) return;
    const std::size_t off = static_cast<std::size_t>(j) * W;
    J.k->products(J.x + off, J.y + off, slot(0, j), slot(1, j), slot(2, j), slot(3, j), slot(4, j), W);
  };

  for (int j = std::max(0, r0 - kRadius); j < r0 + kRadius; ++j) fillRow(j);
  for (int r = r0; r < r1;) {
    const RowGroup p = groupAt(r, r1);
    for (int t = 0; t < p.count; ++t) fillRow(r + kRadius + t);
    for (int m = 0; m < kMaps; ++m) {
      float* out[kGroup];
      for (int t = 0; t < kGroup; ++t) out[t] = hrow + (t * kMaps + m) * S;
      filterMap(
          J, [&](int j) { return slot(m, j); }, p, v, out);
    }
    for (int t = 0; t < p.count; ++t) {
      const int row = r + t;
      const std::size_t off = static_cast<std::size_t>(row) * W;
      const float* h = hrow + t * kMaps * S;
      const Filtered f{h, h + S, h + 2 * S, h + 3 * S, h + 4 * S, J.wx, J.wy[row]};
      if (J.ssim_grad)
        J.k->pointGrad(f, om, J.da + row * J.dstride, J.db + row * J.dstride, J.dc + row * J.dstride, W, J.ssim_scale);
      else
        J.k->point(f, om, W);
      J.row_om[row] = sumChunked<false>(om, W);
      const float* d = slot(2, row);  // this row's x - y, still in the ring
      J.row_l1[row] = sumChunked<true>(d, W);
      if (J.grad && !J.ssim_grad) J.k->sign(d, J.grad + off, W, J.l1_scale);
    }
    r += p.count;
  }
}

// Backward over rows [r0, r1): filters the partial maps (G^T = G) and applies the chain
// rule grad = l1 + G*a + y' G*c + 2 (x - y) G*b.
void backwardBlock(const Job& J, int r0, int r1) {
  const std::size_t W = J.W, S = rowStride(W);
  std::vector<float>& buf = scratch(kGroup * rowStride(W + 2 * J.pad) + kGroup * 3 * S);
  float* v[kGroup];
  float* hrow = paddedRows(J, buf.data(), v);  // kGroup x 3 filtered rows
  const float* maps[3] = {J.da, J.db, J.dc};
  for (int r = r0; r < r1;) {
    const RowGroup p = groupAt(r, r1);
    for (int m = 0; m < 3; ++m) {
      float* out[kGroup];
      for (int t = 0; t < kGroup; ++t) out[t] = hrow + (t * 3 + m) * S;
      filterMap(
          J, [&](int j) { return maps[m] + static_cast<std::size_t>(j) * J.dstride; }, p, v, out);
    }
    for (int t = 0; t < p.count; ++t) {
      const std::size_t off = static_cast<std::size_t>(r + t) * W;
      const float* h = hrow + t * 3 * S;
      J.k->combine(J.x + off, J.y + off, h, h + S, h + 2 * S, J.grad + off, W, J.l1_scale);
    }
    r += p.count;
  }
}

template <typename F>
void forRowBlocks(int h, F&& f) {
  const int blocks = (h + kBlockRows - 1) / kBlockRows;
  tbb::parallel_for(
      tbb::blocked_range<int>(0, blocks, 1),
      [&](const tbb::blocked_range<int>& br) {
        const FloatEnvGuard fenv;  // geometry/float_env.h
        for (int b = br.begin(); b != br.end(); ++b) f(b * kBlockRows, std::min(h, (b + 1) * kBlockRows));
      },
      tbb::simple_partitioner());
}

}  // namespace

SsimIsa ssimBestIsa() {
#if SARESGS_SSIM_AVX2
  static const SsimIsa best = [] {
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl")) return SsimIsa::kAvx512;
    return __builtin_cpu_supports("avx2") ? SsimIsa::kAvx2 : SsimIsa::kBaseline;
  }();
  return best;
#else
  return SsimIsa::kBaseline;
#endif
}

void ssimLimitIsa(SsimIsa widest) { g_widest.store(static_cast<int>(widest), std::memory_order_relaxed); }

SsimL1Sums ssimL1(const float* x, const float* y, int w, int h, int channels, float* grad, double l1_scale,
                  double ssim_scale) {
  Job J{};
  J.x = x;
  J.y = y;
  J.h = h;
  J.channels = channels;
  J.W = static_cast<std::size_t>(w) * channels;
  J.pad = static_cast<std::size_t>(kRadius) * channels;
  J.grad = grad;
  J.l1_scale = static_cast<float>(l1_scale);
  J.ssim_scale = static_cast<float>(ssim_scale);
  J.ssim_grad = grad != nullptr && ssim_scale != 0.0;
  J.k = &kernels();
  // The call's buffers, kept per thread between calls (splat/kept_buffers.h).
  KeptBuffers<CallBuffers> kept;
  CallBuffers& B = kept.get();
  B.zeros.assign(J.W, 0.0f);
  J.zeros = B.zeros.data();
  B.wx.resize(J.W);
  B.wy.resize(static_cast<std::size_t>(h));
  for (int i = 0; i < w; ++i)
    std::fill_n(B.wx.begin() + static_cast<std::ptrdiff_t>(i) * channels, channels,
                static_cast<float>(insideWeight(i, w)));
  for (int r = 0; r < h; ++r) B.wy[static_cast<std::size_t>(r)] = static_cast<float>(insideWeight(r, h));
  J.wx = B.wx.data();
  J.wy = B.wy.data();
  B.row_om.assign(static_cast<std::size_t>(h), 0.0);
  B.row_l1.assign(static_cast<std::size_t>(h), 0.0);
  J.row_om = B.row_om.data();
  J.row_l1 = B.row_l1.data();
  if (J.ssim_grad) {
    J.dstride = rowStride(J.W);
    const std::size_t n = J.dstride * h;
    B.partials.resize(3 * n);
    J.da = B.partials.data();
    J.db = J.da + n;
    J.dc = J.db + n;
  }
  const std::vector<double>& row_om = B.row_om;
  const std::vector<double>& row_l1 = B.row_l1;

  forRowBlocks(h, [&](int r0, int r1) { forwardBlock(J, r0, r1); });
  if (J.ssim_grad) forRowBlocks(h, [&](int r0, int r1) { backwardBlock(J, r0, r1); });

  SsimL1Sums s;
  for (int r = 0; r < h; ++r) {
    s.one_minus_ssim += row_om[r];
    s.abs_diff += row_l1[r];
  }
  return s;
}

}  // namespace saresgs
