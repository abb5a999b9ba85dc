// The float tile kernels (see splat/raster/raster_kernels.h), KernelIsa::kLanes pixels at
// a time with GCC/Clang vector extensions: the lanes, the exponentials, the tile walk and
// the forward composite here; the backward and Fisher passes in
// splat/raster/raster_kernels_backward_impl.h, the pair kernels in
// splat/raster/raster_kernels_pair_impl.h, the projection in
// splat/raster/project_kernels_impl.h. Included once per instruction set, by a file that
// first names its options in namespace saresgs::raster_kernels (raster_kernels.h):
//   using KernelIsa = Avx2Isa;  (or BaselineIsa, Avx512Isa, KernelOptions<8, false, false>)
// Everything here has internal linkage (an unnamed namespace) and deliberately includes
// no library header with inline code of its own beyond <cmath> and <cstring> builtins, so
// that a compilation for AVX2 emits no function the linker could share with the baseline
// one; the including file hands its kernels to the rasterizer as a KernelSet.
#pragma once
#include <cmath>
#include <cstdint>
#include <cstring>

#if defined(__x86_64__)
#include <immintrin.h>  // intrinsics are always-inline, no symbols of their own
#endif

#include "splat/raster/constants.h"
#include "splat/raster/raster_kernels.h"

namespace saresgs::raster_kernels {
namespace {

constexpr int L = KernelIsa::kLanes;
static_assert(L == 4 || L == 8);
static_assert(!KernelIsa::kFma || L == 8, "the FMA kernels are eight lanes wide");
#if !defined(__x86_64__)
static_assert(!KernelIsa::kFma, "the FMA kernels are x86-64's");
#endif
// The contract's constants (splat/raster/constants.h) under the kernels' short names.
constexpr int kTile = kTileSize;
constexpr float kMinA = kMinAlpha;
constexpr float kMaxA = kMaxAlpha;
constexpr float kMinT = kMinTransmittance;
constexpr int kSlot = 9;

typedef float vf __attribute__((vector_size(4 * L)));
typedef std::int32_t vi __attribute__((vector_size(4 * L)));

// a b + c: one fused rounding where the kernels are built for FMA, else two. (The
// helpers that reach for intrinsics are templates on the vector type, so that the branch
// another instruction set would take is never instantiated.)
// Off x86-64 only the portable branches exist.
template <typename V>
inline V fma(V a, V b, V c) {
#if defined(__x86_64__)
  if constexpr (KernelIsa::kFma)
    return reinterpret_cast<V>(
        _mm256_fmadd_ps(reinterpret_cast<__m256>(a), reinterpret_cast<__m256>(b), reinterpret_cast<__m256>(c)));
  else
#endif
    return a * b + c;
}

// x in every lane. Written as a scalar-vector operation so that GCC emits one broadcast
// (a per-lane loop became a chain of inserts); x - (+0) is x exactly, -0 included.
inline vf vs(float x) { return x - vf{}; }
// A tile's pixels are stored in blocks of kBW x kBH pixels, one block per vector: four
// columns by one row for four lanes, four by two for eight. The Gaussians are small
// (a few pixels across), so a squarer block wastes fewer lanes on pixels they miss than
// a row of eight would.
constexpr int kBW = 4;
constexpr int kBH = L / kBW;
constexpr int kBX = kTile / kBW;  // blocks per block row
static_assert(kTile % kBW == 0 && kTile % kBH == 0);
// The tile row and column of storage index k.
inline int blockRow(int k) { return (k / L) / kBX * kBH + (k % L) / kBW; }
inline int blockCol(int k) { return (k / L) % kBX * kBW + (k % L) % kBW; }
inline vf laneColCentres() {  // 0.5, 1.5, 2.5, 3.5, 0.5, ...
  vf v;
  for (int i = 0; i < L; ++i) v[i] = static_cast<float>(i % kBW) + 0.5f;
  return v;
}
inline vf laneRowCentres() {  // 0.5 x4, then 1.5 x4 for eight lanes
  vf v;
  for (int i = 0; i < L; ++i) v[i] = static_cast<float>(i / kBW) + 0.5f;
  return v;
}
inline vf load(const float* p) {
  vf v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store(float* p, vf v) { std::memcpy(p, &v, sizeof v); }
// Lanes summed as a balanced tree ((v0 + v1) + (v2 + v3)) + ..., a fixed order.
inline float hsum(vf v) {
  float s[L];
  std::memcpy(s, &v, sizeof v);
  for (int n = L / 2; n >= 1; n /= 2)
    for (int i = 0; i < n; ++i) s[i] = s[2 * i] + s[2 * i + 1];
  return s[0];
}
inline int hsumInt(vi v) {
  int s = 0;
  for (int i = 0; i < L; ++i) s += v[i];
  return s;
}

// A block's L values of a whole-image array (row stride W) at tile offset (c, r): kBW
// consecutive values from each of its kBH rows, loaded as vectors (no lane-by-lane stores
// that a full-width load would then wait on), and stored back the same way.
typedef float v4f __attribute__((vector_size(16)));
typedef std::int32_t v4i __attribute__((vector_size(16)));
template <typename V4, typename V, typename S>
inline V loadRows(const S* p, std::size_t W) {
  V4 a;
  std::memcpy(&a, p, sizeof a);
  if constexpr (L == 4) {
    return a;
  } else {
    V4 b;
    std::memcpy(&b, p + W, sizeof b);
    return __builtin_shufflevector(a, b, 0, 1, 2, 3, 4, 5, 6, 7);
  }
}
template <typename V4, typename V, typename S>
inline void storeRows(S* p, std::size_t W, V v) {
  const V4 a = __builtin_shufflevector(v, v, 0, 1, 2, 3);
  std::memcpy(p, &a, sizeof a);
  if constexpr (L == 8) {
    const V4 b = __builtin_shufflevector(v, v, 4, 5, 6, 7);
    std::memcpy(p + W, &b, sizeof b);
  }
}
// The three channels of kBW interleaved RGB pixels (12 floats) apart.
inline void deinterleave3(const float* p, v4f& c0, v4f& c1, v4f& c2) {
  v4f x0, x1, x2;
  std::memcpy(&x0, p, 16);
  std::memcpy(&x1, p + 4, 16);
  std::memcpy(&x2, p + 8, 16);
  typedef float v8f __attribute__((vector_size(32)));
  const v8f ab = __builtin_shufflevector(x0, x1, 0, 1, 2, 3, 4, 5, 6, 7);
  const v8f cc = __builtin_shufflevector(x2, x2, 0, 1, 2, 3, 0, 1, 2, 3);
  c0 = __builtin_shufflevector(ab, cc, 0, 3, 6, 9);
  c1 = __builtin_shufflevector(ab, cc, 1, 4, 7, 10);
  c2 = __builtin_shufflevector(ab, cc, 2, 5, 8, 11);
}
inline void interleave3(float* p, v4f c0, v4f c1, v4f c2) {
  typedef float v8f __attribute__((vector_size(32)));
  const v8f a = __builtin_shufflevector(c0, c1, 0, 1, 2, 3, 4, 5, 6, 7);
  const v8f b = __builtin_shufflevector(c2, c2, 0, 1, 2, 3, 0, 1, 2, 3);
  const v4f x0 = __builtin_shufflevector(a, b, 0, 4, 8, 1);
  const v4f x1 = __builtin_shufflevector(a, b, 5, 9, 2, 6);
  const v4f x2 = __builtin_shufflevector(a, b, 10, 3, 7, 11);
  std::memcpy(p, &x0, 16);
  std::memcpy(p + 4, &x1, 16);
  std::memcpy(p + 8, &x2, 16);
}
// Two rows' kBW lanes as one block vector, and back (templates, so that the shuffle of
// the other lane count is never instantiated).
template <typename V4>
inline vf joinRows(V4 a, [[maybe_unused]] V4 b) {
  if constexpr (L == 4)
    return a;
  else
    return __builtin_shufflevector(a, b, 0, 1, 2, 3, 4, 5, 6, 7);
}
template <typename V>
inline v4f rowOf(V v, [[maybe_unused]] int half) {
  if constexpr (L == 4)
    return v;
  else
    return half == 0 ? __builtin_shufflevector(v, v, 0, 1, 2, 3) : __builtin_shufflevector(v, v, 4, 5, 6, 7);
}

// a < b ? a : b and a > b ? a : b, lane by lane (b where unordered): one min/max
// instruction where the target has it (GCC keeps a vector ternary as compare + blend).
template <typename V>
inline V vmin(V a, V b) {
#if defined(__x86_64__)
  if constexpr (KernelIsa::kFma)
    return reinterpret_cast<V>(_mm256_min_ps(reinterpret_cast<__m256>(a), reinterpret_cast<__m256>(b)));
  else if constexpr (L == 4)
    return reinterpret_cast<V>(_mm_min_ps(reinterpret_cast<__m128>(a), reinterpret_cast<__m128>(b)));
  else
#endif
    return a < b ? a : b;
}
template <typename V>
inline V vmax(V a, V b) {
#if defined(__x86_64__)
  if constexpr (KernelIsa::kFma)
    return reinterpret_cast<V>(_mm256_max_ps(reinterpret_cast<__m256>(a), reinterpret_cast<__m256>(b)));
  else if constexpr (L == 4)
    return reinterpret_cast<V>(_mm_max_ps(reinterpret_cast<__m128>(a), reinterpret_cast<__m128>(b)));
  else
#endif
    return a > b ? a : b;
}

// The square root lane by lane (correctly rounded, as std::sqrt).
template <typename V>
inline V vsqrt(V a) {
#if defined(__x86_64__)
  if constexpr (KernelIsa::kFma) {
    return reinterpret_cast<V>(_mm256_sqrt_ps(reinterpret_cast<__m256>(a)));
  } else if constexpr (L == 4) {
    return reinterpret_cast<V>(_mm_sqrt_ps(reinterpret_cast<__m128>(a)));
  } else
#endif
  {
    for (int i = 0; i < L; ++i) a[i] = std::sqrt(a[i]);
    return a;
  }
}

// 2^x for x <= 0 without a libm call, on a short dependency chain (the kernels are
// bound by its latency, not by instruction count): x = n + r with n = round(x) by the
// 1.5 * 2^23 trick (the sum's low mantissa bits are n; r = x - n is exact), and 2^r,
// |r| <= 1/2, by its degree-6 Taylor polynomial in Estrin's form (relative error
// < 2e-7). x is clamped to -125 so that 2^n stays a normal float: below it the result
// is 2^-125 (~2.4e-38) instead of 2^x, which the kernels never see, as they use G only
// where o G >= 1/255.
inline vf exp2Core(vf xc) {
  const vf magic = vs(12582912.0f);  // 1.5 * 2^23
  const vf m = xc + magic;           // rounds to the nearest whole number (even on ties)
  const vf n = m - magic;
  const vf r = xc - n;
  const vf r2 = r * r;
  const vf lo = fma(vs(0.6931471805599453f), r, vs(1.0f));
  const vf mid = fma(vs(0.05550410866482158f), r, vs(0.2402265069591007f));
  const vf hi = fma(vs(0.0013333558146428443f), r, vs(0.009618129107628477f));
  const vf p = fma(r2 * r2, fma(vs(0.00015403530393381608f), r2, hi), fma(r2, mid, lo));
  const vf scale = reinterpret_cast<vf>((reinterpret_cast<vi>(m) - (0x4B400000 - 127)) << 23);
  return p * scale;
}
inline vf exp2NonPositive(vf x) {
  return exp2Core(vmax(vs(-125.0f), x));  // -125 where x < -125 (x is never NaN here)
}
// 2^x for x in [-125, 125] (clamped there), the same polynomial: the lattice's step
// factors (forEachBlock), which may exceed 1.
inline vf exp2Clamped(vf x) { return exp2Core(vmin(vs(125.0f), vmax(vs(-125.0f), x))); }

// A Gaussian's exponent is evaluated in base 2 (power * log2 e, so G = 2^power2): the
// factor is folded into its per-Gaussian coefficients, not paid per pixel.
constexpr float kLog2e = 1.4426950408889634f;

// The row terms of a Gaussian's base-2 exponent, hoisted out of the pixel loops; per
// lane, as a block spans kBH rows, in the same operation order for every block shape.
inline vf rowQuad(const TileGaussian<float>& q, vf dy) { return (vs(-0.5f * kLog2e * q.c) * dy) * dy; }
inline vf rowCross(const TileGaussian<float>& q, vf dy) { return vs(kLog2e * q.b) * dy; }

// One Gaussian at L pixel centres of a row: the quantities both kernels need, computed
// in one place so that the forward and backward passes make identical threshold
// decisions. `touches` is rule 4's rectangle test in x plus the alpha test (o G >= 1/255
// is alpha >= 1/255, as 0.99 > 1/255); the row's y test is the caller's.
struct Lanes {
  vf dx, G, oG, alpha;
  vi touches;
};

// The lanes of a block whose G is known (from evalLanes' exponent or from forEachBlock's
// lattice): o G, the clamped alpha, and the rectangle test in x plus the alpha test.
inline Lanes lanesOfG(vf dx, vf G, vf o, vf hx, vi row_in) {
  Lanes l;
  l.dx = dx;
  l.G = G;
  l.oG = o * G;
  l.alpha = vmin(l.oG, vs(kMaxA));
  const vf adx = reinterpret_cast<vf>(reinterpret_cast<vi>(dx) & 0x7fffffff);
  l.touches = row_in & (adx <= hx) & (l.oG >= vs(kMinA));
  return l;
}

inline Lanes evalLanes(vf dx, vf ha, vf qy, vf by, vf o, vf hx, vi row_in) {
  // ((-0.5 a log2e) dx) dx + row_quad - row_cross dx: the exponent in base 2.
  vf power;
  if constexpr (KernelIsa::kFma)
    power = fma(-by, dx, fma(ha * dx, dx, qy));
  else
    power = ha * dx * dx + qy - by * dx;
  Lanes l = lanesOfG(dx, exp2NonPositive(vmin(power, vs(0.0f))), o, hx, row_in);  // power < 0 ? power : 0
  l.touches = l.touches & (power <= vs(0.0f));
  return l;
}

// A Gaussian's pixel span (TileGaussian::px0.., a superset of the pixels that can pass
// the per-pixel rectangle test) as offsets from `origin`, clipped to [0, limit - origin):
// integer clipping only, no branches. The per-pixel test decides; this only bounds the
// loops (empty when lo > hi).
inline void tileSpan(std::int32_t span_lo, std::int32_t span_hi, int origin, int limit, int& lo, int& hi) {
  lo = span_lo - origin;
  hi = span_hi - origin;
  lo = lo > 0 ? lo : 0;
  hi = hi < limit - origin - 1 ? hi : limit - origin - 1;
}

// The columns [lo[rb], hi[rb]] (tile offsets, within the Gaussian's span [c0, c1]) that
// the Gaussian may touch in each block row rb of [rb0, rbl]: its rows' alpha-ellipse chords
// (TileGaussian::chord_*, widened against rounding) all lie within [min centre - widest
// half, max centre + widest half], plus 0.01 px for the centres' own rounding. One square
// root per block row; empty (lo > hi) when no row of the block meets the ellipse. Loop
// bounds only: the per-pixel test decides. L block rows per vector, with selects: one
// row at a time in scalar code (the same operations, so the same bounds) it would be a
// chain of conversions and compares per block row, about a tenth of the backward
// kernel's cycles on room360 at 512x384, with early returns whose branches mispredict.
constexpr int kBlockRows = kTile / kBH;
inline void blockRowSpans(const TileGaussian<float>& g, int x0, int y0, int rb0, int rbl, int c0, int c1, int* lo,
                          int* hi) {
  const vf c0f = vs(static_cast<float>(c0)), c1f = vs(static_cast<float>(c1));
  const vi c0v = vi{} + c0, c1v = vi{} + c1;
  for (int base = rb0 - rb0 % L; base <= rbl; base += L) {
    vi rows;
    for (int i = 0; i < L; ++i) rows[i] = y0 + (base + i) * kBH;
    const vf dy0 = (__builtin_convertvector(rows, vf) + vs(0.5f)) - vs(g.my);
    const vf dy1 = dy0 + vs(static_cast<float>(kBH - 1));
    const vf zero = vs(0.0f);
    const vf dmin = dy0 > zero ? dy0 : (dy1 < zero ? dy1 : zero);
    const vf t = vs(g.chord_k0) - vs(g.chord_k1) * (dmin * dmin);
    const vf half = vsqrt(t > zero ? t : zero) + vs(0.01f);
    const vf xa = (vs(g.mx) + vs(g.chord_slope) * dy0) - vs(static_cast<float>(x0));
    const vf xb = (vs(g.mx) + vs(g.chord_slope) * dy1) - vs(static_cast<float>(x0));
    vf l = ((xa < xb ? xa : xb) - half) - vs(0.5f), u = ((xa < xb ? xb : xa) + half) - vs(0.5f);
    l = l >= c0f ? l : c0f;
    u = u <= c1f ? u : c1f;
    l = l <= c1f + vs(1.0f) ? l : c1f + vs(1.0f);
    u = u >= c0f - vs(1.0f) ? u : c0f - vs(1.0f);
    const vi lt = __builtin_convertvector(l, vi), ut = __builtin_convertvector(u, vi);  // truncation
    const vi li = lt - (__builtin_convertvector(lt, vf) < l);                           // masks are -1: ceiling, l >= 0
    const vi ui = ut + (__builtin_convertvector(ut, vf) > u);                           // floor, u >= -1
    const vi none = ~(t >= zero);
    const vi lov = none ? c1v + 1 : li, hiv = none ? c0v - 1 : ui;
    for (int i = 0; i < L && base + i < kBlockRows; ++i) {
      lo[base + i] = lov[i];
      hi[base + i] = hiv[i];
    }
  }
}

// m ? v : +0 lane by lane (m is -1 or 0), as a bitwise and: the same bits as the select,
// and on AVX-512VL GCC keeps it a vector operation (a select on a mask combined from two
// compares was rebuilt lane by lane in general-purpose registers).
inline vf maskOr0(vi m, vf v) { return reinterpret_cast<vf>(m & reinterpret_cast<vi>(v)); }

inline vi absLe(vf v, vf bound) { return reinterpret_cast<vf>(reinterpret_cast<vi>(v) & 0x7fffffff) <= bound; }

constexpr int kBlocks = kTile * kTile / L;  // vector blocks per tile

// The lattice (forEachBlock): a Gaussian's base-2 exponent is a quadratic
// p(dx, dy) = al dx^2 + be dx dy + ga dy^2, so along a row of blocks (dx += kBW) the
// factor from one block's G to the next, 2^(p(dx + kBW) - p(dx)), changes by the constant
// factor 2^(2 al kBW^2), and from one block row to the next (dy += kBH) G changes by
// 2^(p(dy + kBH) - p(dy)), which changes by 2^(2 ga kBH^2), while the row factor changes
// by 2^(kBW kBH be). Three exponentials of eight lanes and one of the constants give
// every block's G by products: two multiplications per block instead of the exponent and
// exp2. Used where every lane of the Gaussian's block rectangle has p >= kLatticeFloor,
// so that every G and every step factor inside it is a normal float, and where the
// rectangle has at least kLatticeMinBlocks blocks (below it the four exponentials cost
// more than they save). G's relative error is then the first block's three exponents'
// rounding (terms up to |kLatticeFloor|) plus one rounding per product, at most 4 + 8 + 4
// in a 16-pixel tile: up to 1.4e-5 measured with eight lanes and 2.0e-5 with four,
// against up to 1.1e-4 for the exponent per block on needle-like Gaussians, whose terms
// cancel (TileWalk.*, tests/splat/raster/test_raster_lattice.cpp). Every kernel walks
// the same lattice, so the forward, backward and Fisher passes make identical decisions.
constexpr float kLatticeFloor = -100.0f;
constexpr int kLatticeMinBlocks = 5;

struct Lattice {
  float al, be, ga;  // the exponent's coefficients in base 2
};

// Whether Gaussian g's block rectangle (columns [cb0, cbl + kBW), rows [rb0 kBH,
// (rbl + 1) kBH) of the tile at x0, y0) suits the lattice: at least kLatticeMinBlocks
// blocks, and p >= kLatticeFloor at its corners (a concave quadratic takes its minimum
// over a rectangle at a corner; NaN coefficients fail every comparison).
inline bool latticeFits(const TileGaussian<float>& g, int x0, int y0, int cb0, int cbl, int rb0, int rbl, Lattice& lt) {
  if (((cbl - cb0) / kBW + 1) * (rbl - rb0 + 1) < kLatticeMinBlocks) return false;
  lt.al = -0.5f * kLog2e * g.a;
  lt.be = -kLog2e * g.b;
  lt.ga = -0.5f * kLog2e * g.c;
  const float sx = 2.0f * kBW * kBW * lt.al, sy = 2.0f * kBH * kBH * lt.ga, sxy = kBW * kBH * lt.be;
  if (!(sx >= kLatticeFloor && sy >= kLatticeFloor && sxy >= kLatticeFloor && sxy <= -kLatticeFloor)) return false;
  const float X0 = static_cast<float>(x0 + cb0) + 0.5f - g.mx;
  const float X1 = static_cast<float>(x0 + cbl + kBW - 1) + 0.5f - g.mx;
  const float Y0 = static_cast<float>(y0 + rb0 * kBH) + 0.5f - g.my;
  const float Y1 = static_cast<float>(y0 + rbl * kBH + kBH - 1) + 0.5f - g.my;
  auto P = [&](float x, float y) { return (lt.al * x + lt.be * y) * x + lt.ga * y * y; };
  const float p00 = P(X0, Y0), p01 = P(X0, Y1), p10 = P(X1, Y0), p11 = P(X1, Y1);
  return p00 >= kLatticeFloor && p01 >= kLatticeFloor && p10 >= kLatticeFloor && p11 >= kLatticeFloor;
}

// Calls body(block, lanes, dy) for every block of the tile [x0, x1) x [y0, y1) that
// Gaussian g may touch (its rectangle, narrowed per block row by blockRowSpan), row by
// row and left to right: the one pixel loop of every kernel. Pixel centres are whole
// numbers + 0.5, exact in float, so stepping them by kBW gives the same offsets as
// computing each afresh. G comes from the lattice above where it fits, else from
// evalLanes' exponent and exp2 per block.
template <typename Body>
__attribute__((always_inline)) inline void forEachBlock(const TileGaussian<float>& g, int x0, int y0, int x1, int y1,
                                                        Body&& body) {
  int c0, c1, r0, r1;
  tileSpan(g.px0, g.px1, x0, x1, c0, c1);
  tileSpan(g.py0, g.py1, y0, y1, r0, r1);
  if (c0 > c1 || r0 > r1) return;
  const vf mx = vs(g.mx), my = vs(g.my), hx = vs(g.hx), hy = vs(g.hy), o = vs(g.o);
  const vf lane_x = laneColCentres(), lane_y = laneRowCentres();
  // Chords (blockRowSpan) only for Gaussians wider than kChordMinSpan pixels: for the
  // small ones, which are most pairs, a block row's span costs more than the blocks it
  // saves (without chords below that width, bench step 512x384 was 18 % faster at 20k
  // and 100k Gaussians and 1500 training iterations on room360 13 % faster, same
  // output); a long thin Gaussian across a tile still skips the blocks it misses.
  const bool narrow = g.px1 - g.px0 + 1 > kChordMinSpan;
  const int rb0 = r0 / kBH, rbl = r1 / kBH;
  int row_lo[kBlockRows], row_hi[kBlockRows];
  if (narrow) blockRowSpans(g, x0, y0, rb0, rbl, c0, c1, row_lo, row_hi);
  {
    const int cb0 = c0 & ~(kBW - 1), cbl = c1 & ~(kBW - 1);
    Lattice lt;
    if (latticeFits(g, x0, y0, cb0, cbl, rb0, rbl, lt)) {
      const vf dx0 = (vs(static_cast<float>(x0 + cb0)) + lane_x) - mx;
      const vf dy0 = (vs(static_cast<float>(y0 + rb0 * kBH)) + lane_y) - my;
      const vf al = vs(lt.al), be = vs(lt.be), ga = vs(lt.ga);
      // G at the first block, its step factor to the right and its step factor down.
      vf g_row = exp2Clamped(fma(al * dx0 + be * dy0, dx0, ga * dy0 * dy0));
      vf e_row = exp2Clamped(
          fma(al, fma(vs(2.0f * kBW), dx0, vs(static_cast<float>(kBW * kBW))), vs(static_cast<float>(kBW)) * be * dy0));
      vf f = exp2Clamped(
          fma(ga, fma(vs(2.0f * kBH), dy0, vs(static_cast<float>(kBH * kBH))), vs(static_cast<float>(kBH)) * be * dx0));
      vf kv = vs(0.0f);
      kv[0] = 2.0f * kBW * kBW * lt.al;
      kv[1] = 2.0f * kBH * kBH * lt.ga;
      kv[2] = kBW * kBH * lt.be;
      kv = exp2Clamped(kv);
      const vf kx = vs(kv[0]), ky = vs(kv[1]), kxy = vs(kv[2]);
      for (int rb = rb0; rb <= rbl; ++rb) {
        // A wide Gaussian's rows skip the blocks its chord misses (the lattice still
        // steps over them: two multiplications each, in the same order as in a row
        // that visits them).
        const int lo = narrow ? row_lo[rb] : c0, hi = narrow ? row_hi[rb] : c1;
        if (lo <= hi) {
          const vf dy = (vs(static_cast<float>(y0 + rb * kBH)) + lane_y) - my;
          const vi row_in = absLe(dy, hy);
          vf G = g_row, e = e_row;
          int cb = cb0;
          for (const int first = lo & ~(kBW - 1); cb < first; cb += kBW) {
            G = G * e;
            e = e * kx;
          }
          vf px = vs(static_cast<float>(x0 + cb)) + lane_x;
          int blk = rb * kBX + cb / kBW;
          for (; cb <= hi; cb += kBW, ++blk, px = px + vs(static_cast<float>(kBW))) {
            body(blk, lanesOfG(px - mx, G, o, hx, row_in), dy);
            G = G * e;
            e = e * kx;
          }
        }
        g_row = g_row * f;
        f = f * ky;
        e_row = e_row * kxy;
      }
      return;
    }
  }
  const vf ha = vs(-0.5f * kLog2e) * vs(g.a);
  for (int rb = rb0; rb <= rbl; ++rb) {
    const int lo = narrow ? row_lo[rb] : c0, hi = narrow ? row_hi[rb] : c1;
    if (lo > hi) continue;
    const vf dy = (vs(static_cast<float>(y0 + rb * kBH)) + lane_y) - my;
    const vi row_in = absLe(dy, hy);
    const vf qy = rowQuad(g, dy), by = rowCross(g, dy);
    const int cb0 = lo & ~(kBW - 1);
    vf px = vs(static_cast<float>(x0 + cb0)) + lane_x;
    int blk = rb * kBX + cb0 / kBW;
    for (int cb = cb0; cb <= hi; cb += kBW, ++blk, px = px + vs(static_cast<float>(kBW)))
      body(blk, evalLanes(px - mx, ha, qy, by, o, hx, row_in), dy);
  }
}

// --- Forward ------------------------------------------------------------------------
// One vector block of a tile's compositing state. A stopped pixel keeps its
// transmittance with the sign flipped (it is >= 1e-4 while the pixel is live), so no
// separate "active" flag; pixels beyond the image start stopped.
struct ForwardBlock {
  vf Tr, C0, C1, C2, D, walked, contrib;
};

struct ForwardState {
  ForwardBlock b[kBlocks];
  int n_active = 0;

  void init(int w, int h) {
    n_active = w * h;
    if (w == kTile && h == kTile) {  // a whole tile: every pixel live
      for (ForwardBlock& B : b) {
        B.Tr = vs(1.0f);
        B.C0 = B.C1 = B.C2 = B.D = B.walked = B.contrib = vs(0.0f);
      }
      return;
    }
    for (int k = 0; k < kTile * kTile; ++k) {
      ForwardBlock& B = b[k / L];
      const int i = k % L;
      B.Tr[i] = blockCol(k) < w && blockRow(k) < h ? 1.0f : -1.0f;
      B.C0[i] = B.C1[i] = B.C2[i] = B.D[i] = B.walked[i] = B.contrib[i] = 0.0f;
    }
  }

  // Rule 7 for one Gaussian (entry jf - 1) at one block; returns the lanes it stops.
  // kAux: also the depth and contributor sums (a training step needs neither: without
  // them a block's step is two updates, two loads and two stores shorter; every other
  // value is computed by the same operations either way).
  template <bool kAux>
  static inline vi step(ForwardBlock& B, const Lanes& Ln, vf col0, vf col1, vf col2, vf dep, vf jf) {
    const vf alpha = Ln.alpha;
    const vf t = B.Tr;
    const vi ok = (t > vs(0.0f)) & Ln.touches;
    const vf next = t * (vs(1.0f) - alpha);
    const vi stop = ok & (next < vs(kMinT));
    const vi take = ok & ~stop;
    const vf wgt = maskOr0(take, alpha * t);
    B.C0 = fma(wgt, col0, B.C0);
    B.C1 = fma(wgt, col1, B.C1);
    B.C2 = fma(wgt, col2, B.C2);
    if constexpr (kAux) B.D = fma(wgt, dep, B.D);
    const vf flipped = reinterpret_cast<vf>(reinterpret_cast<vi>(t) ^ (stop & static_cast<std::int32_t>(0x80000000u)));
    B.Tr = take ? next : flipped;  // flipped: -t where stopping, else t
    B.walked = take ? jf : B.walked;
    if constexpr (kAux) B.contrib = B.contrib + maskOr0(take, vs(1.0f));
    return stop;
  }

  // kAux: out.depth and out.contributors are written too (else they are null and untouched).
  template <bool kAux>
  void write(int x0, int y0, int w, int h, const float bg[3], const ForwardOut& out) const {
    if (w == kTile && h == kTile) {
      // A whole tile, a block at a time: the per-pixel loop below, lane by lane (the same
      // operations on every value), with vector loads and stores.
      const std::size_t W = static_cast<std::size_t>(out.W);
      for (int blk = 0; blk < kBlocks; ++blk) {
        const ForwardBlock& B = b[blk];
        const std::size_t pix = static_cast<std::size_t>(y0 + blk / kBX * kBH) * W + (x0 + blk % kBX * kBW);
        const vf T = reinterpret_cast<vf>(reinterpret_cast<vi>(B.Tr) & 0x7fffffff);
        const vf r = B.C0 + T * vs(bg[0]), g = B.C1 + T * vs(bg[1]), bl = B.C2 + T * vs(bg[2]);
        const vf a = vs(1.0f) - T;
        for (int half = 0; half < kBH; ++half)
          interleave3(out.rgb + (pix + half * W) * 3, rowOf(r, half), rowOf(g, half), rowOf(bl, half));
        storeRows<v4f>(out.alpha + pix, W, a);
        if constexpr (kAux) {
          const vi covered = a >= vs(1e-6f);
          const vf depth = covered ? B.D / (covered ? a : vs(1.0f)) : vs(0.0f);
          storeRows<v4f>(out.depth + pix, W, depth);
          storeRows<v4i>(out.contributors + pix, W, __builtin_convertvector(B.contrib, vi));
        }
        storeRows<v4f>(out.final_T + pix, W, T);
        storeRows<v4i>(reinterpret_cast<std::int32_t*>(out.n_walked + pix), W, __builtin_convertvector(B.walked, vi));
      }
      return;
    }
    for (int k = 0; k < kTile * kTile; ++k) {
      const int r = blockRow(k), c = blockCol(k);
      if (r >= h || c >= w) continue;
      const ForwardBlock& B = b[k / L];
      const int i = k % L;
      const float T = std::abs(B.Tr[i]);
      const std::size_t pix = static_cast<std::size_t>(y0 + r) * out.W + (x0 + c);
      out.rgb[pix * 3] = B.C0[i] + T * bg[0];
      out.rgb[pix * 3 + 1] = B.C1[i] + T * bg[1];
      out.rgb[pix * 3 + 2] = B.C2[i] + T * bg[2];
      out.alpha[pix] = 1.0f - T;
      if constexpr (kAux) {
        out.depth[pix] = (1.0f - T) >= 1e-6f ? B.D[i] / (1.0f - T) : 0.0f;
        out.contributors[pix] = static_cast<int>(B.contrib[i]);
      }
      out.final_T[pix] = T;
      out.n_walked[pix] = static_cast<std::uint32_t>(B.walked[i]);
    }
  }
};

// A Gaussian's per-block constants of ForwardState::step.
struct ForwardColour {
  vf col0, col1, col2, dep, jf;
  ForwardColour(const TileGaussian<float>& g, int j)
      : col0(vs(g.col[0])),
        col1(vs(g.col[1])),
        col2(vs(g.col[2])),
        dep(vs(g.depth)),
        jf(vs(static_cast<float>(j + 1))) {}
};

// Front-to-back compositing, Gaussian by Gaussian over the blocks it may touch, so the
// inner loop is branch-free vector code; each pixel sees exactly the per-pixel sequence
// of rule 7.
template <bool kAux>
void compositeTileImpl(const TileGaussian<float>* q, int nq, int x0, int y0, int x1, int y1, const float bg[3],
                       const ForwardOut& out) {
  const int w = x1 - x0, h = y1 - y0;
  ForwardState F;
  F.init(w, h);
  for (int j = 0; j < nq && F.n_active > 0; ++j) {
    const ForwardColour fc(q[j], j);
    vi stopped = vi{} + 0;
    forEachBlock(q[j], x0, y0, x1, y1, [&](int blk, const Lanes& Ln, vf) {
      stopped -= F.step<kAux>(F.b[blk], Ln, fc.col0, fc.col1, fc.col2, fc.dep, fc.jf);  // masks are -1 where true
    });
    F.n_active -= hsumInt(stopped);
  }
  F.write<kAux>(x0, y0, w, h, bg, out);
}

inline void compositeTile(const TileGaussian<float>* q, int nq, int x0, int y0, int x1, int y1, const float bg[3],
                          const ForwardOut& out) {
  if (out.depth)
    compositeTileImpl<true>(q, nq, x0, y0, x1, y1, bg, out);
  else
    compositeTileImpl<false>(q, nq, x0, y0, x1, y1, bg, out);
}

// The machine's floor for the forward kernel's arithmetic (raster_kernels.h): the same
// per-lane work as a training step's compositeTile on the lattice (forEachBlock: G and its
// step factor multiplied on, the opacity, the alpha clamp, the rectangle and alpha tests,
// and ForwardState::step without the depth and contributor sums) on two blocks held in
// registers, with no tile walk, gather or memory traffic, for n rounds. Each round starts
// from a G that moves with the round count, cycling through [0.3, 0.8) so that every value
// stays a normal float (offsets that grew without bound sent an earlier version of this
// loop into denormal operands, whose assists made the "floor" 5-7 times slower than the
// kernels' arithmetic); the checksum keeps the result alive.
inline float compositeFloor(long n) {
  ForwardBlock b[2];
  for (ForwardBlock& B : b) {
    B.Tr = vs(1.0f);
    B.C0 = B.C1 = B.C2 = B.D = B.walked = B.contrib = vs(0.0f);
  }
  const vf o = vs(0.6f), hx = vs(1e6f), mx = vs(2.0f), kx = vs(0.99f);
  const vi row_in = vi{} - 1;
  const vf col0 = vs(0.3f), col1 = vs(0.5f), col2 = vs(0.7f), dep = vs(2.0f), jf = vs(1.0f);
  const vf lane_x = laneColCentres();
  for (long i = 0; i < n; ++i) {
    const float t = static_cast<float>(i & 1023) * (1.0f / 2048.0f);
    vf G = vs(0.3f + t) + lane_x * vs(0.01f), e = vs(0.9f + 0.1f * t);
    vf px = lane_x;
    for (int k = 0; k < 2; ++k, px = px + vs(static_cast<float>(kBW))) {
      ForwardState::step<false>(b[k], lanesOfG(px - mx, G, o, hx, row_in), col0, col1, col2, dep, jf);
      b[k].Tr = vmax(b[k].Tr, vs(0.5f));  // keeps the pixels live (the real blocks mostly are)
      G = G * e;
      e = e * kx;
    }
  }
  return hsum(b[0].C0 + b[1].C0 + b[0].C2 + b[1].C1 + b[0].walked + b[1].walked);
}

}  // namespace
}  // namespace saresgs::raster_kernels
