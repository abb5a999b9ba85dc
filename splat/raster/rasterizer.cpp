// The fast tiled rasterizer: TBB-parallel over Gaussians for projection and over 16x16
// tiles for compositing and backward. Every gradient contribution lands in a slot owned
// by one (tile, Gaussian) pair and slots are reduced per Gaussian in a fixed order, so
// results are bit-identical for the same inputs, whatever the thread count.
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <type_traits>

#include "splat/kept_buffers.h"
#include "splat/raster/execution.h"
#include "splat/raster/projection.h"
#include "splat/raster/raster_kernels.h"
#include "splat/raster/rasterize_detail.h"

// The baseline (four-lane) float kernels; the AVX2 ones are in raster_kernels_avx2.cpp.
#define SARESGS_KERNEL_NS base4
#define SARESGS_KERNEL_LANES 4
#include "splat/raster/raster_kernels_impl.h"
#include "splat/raster/raster_kernels_pair_impl.h"
#include "splat/raster/project_kernels_impl.h"
#include "geometry/float_env.h"
#undef SARESGS_KERNEL_NS
#undef SARESGS_KERNEL_LANES

namespace saresgs {

using projection::CameraT;
using projection::Projected;
using projection::ProjectedGrad;

template <typename T>
struct RasterStateT {
  RasterSettings settings;
  std::vector<Projected<T>> proj;  // per Gaussian
  std::vector<TileGaussian<T>> tile_data;  // per Gaussian: what the tile kernels read
  int tiles_x = 0, tiles_y = 0;
  std::vector<std::uint32_t> gauss_start;  // N + 1: each Gaussian's pairs (k in its range)
  std::vector<std::uint32_t> tile_start;   // tiles + 1
  std::vector<std::uint32_t> entry_gauss;  // per tile entry: the Gaussian
  // Per pair k (Gaussian-major): its tile entry. The backward and Fisher kernels write a
  // pair's slot at its tile entry, so that each tile's slots are one run of memory (at the
  // Gaussian-major index the slots of consecutive pairs landed on scattered cache lines, and
  // the backward stage of bench step 512x384/100k took 1.1-1.2 times as long); the
  // per-Gaussian reductions read them through this map, in pair order.
  std::vector<std::uint32_t> pair_entry;
  std::vector<T> final_T;                  // per pixel
  std::vector<std::uint32_t> n_walked;     // per pixel: tile entries walked (last contributor + 1)
  int isa = 0;                             // the float kernels the forward pass used
};

namespace {

// The arena a pass runs in: the forward pass's execution settings (its thread count
// does not change results, so the backward pass simply reuses it).
template <typename T>
tbb::task_arena& arena(const RasterStateT<T>& st) {
  return raster_execution::arena(st.settings.execution.threads);
}

// The float kernels, indexed by raster_execution::kernelIndex; index 0 is the baseline.
struct KernelSet {
  const char* name;
  raster_kernels::CompositeFn composite;
  raster_kernels::BackwardFn backward;
  raster_kernels::ProjectFn project;
  raster_kernels::ProjectBackwardFn project_backward;
  raster_kernels::FisherChainFn fisher_chain;
};
constexpr KernelSet kKernelSets[] = {
    {"baseline", raster_kernels::base4::compositeTile, raster_kernels::base4::backwardTile,
     raster_kernels::base4::projectRange, raster_kernels::base4::projectBackwardList,
     raster_kernels::base4::fisherChainList},
    {"avx2", raster_kernels::avx2::compositeTile, raster_kernels::avx2::backwardTile,
     raster_kernels::avx2::projectRange, raster_kernels::avx2::projectBackwardList,
     raster_kernels::avx2::fisherChainList},
    // avx512: AVX2's forward; its backward and Fisher walks on 32 registers, bit for bit AVX2's.
    {"avx512", raster_kernels::avx2::compositeTile, raster_kernels::avx512::backwardTile,
     raster_kernels::avx2::projectRange, raster_kernels::avx2::projectBackwardList,
     raster_kernels::avx2::fisherChainList},
};
static_assert(raster_kernels::base4::kProjShC0 == static_cast<float>(kShC0));
static_assert(raster_kernels::base4::kTile == kTileSize && raster_kernels::base4::kMinA == kMinAlpha &&
              raster_kernels::base4::kMaxA == kMaxAlpha && raster_kernels::base4::kMinT == kMinTransmittance);

// Pixel range [lo, hi] whose centres (i + 0.5) lie within mean +- half, clipped to [0, n).
template <typename T>
void pixelRange(T mean, T half, int n, int& lo, int& hi) {
  lo = std::max(0, static_cast<int>(std::ceil(mean - half - T(0.5))));
  hi = std::min(n - 1, static_cast<int>(std::floor(mean + half - T(0.5))));
}

// Pixels i (clipped to [0, n)) whose centres can pass the float test |i + 0.5 - mean| <=
// half: the difference rounds by at most 2^-24 relative, so the exact bound widened by
// 1e-6 relative and 1e-3 px is a superset. Empty (lo > hi) when nothing is finite.
template <typename T>
void pixelSpan(T mean, T half, int n, std::int32_t& lo, std::int32_t& hi) {
  const double h = static_cast<double>(half) * (1.0 + 1e-6) + 1e-3;
  const double l = std::ceil(static_cast<double>(mean) - h - 0.5);
  const double u = std::floor(static_cast<double>(mean) + h - 0.5);
  if (!(l <= u) || !std::isfinite(l) || !std::isfinite(u) || u < 0 || l > n - 1) {
    lo = 1, hi = 0;
    return;
  }
  lo = static_cast<std::int32_t>(std::max(l, 0.0));
  hi = static_cast<std::int32_t>(std::min(u, static_cast<double>(n - 1)));
}

// A projected Gaussian as the tile kernels read it. The chord terms (splat/raster/raster_kernels.h):
// a pixel at offset (dx, dy) can pass o G >= 1/255 only where a dx^2 + 2 b dx dy + c dy^2
// <= k2 = 2 ln(255 o), i.e. |dx + (b/a) dy| <= sqrt(k2/a - (det/a^2) dy^2), det = ac - b^2.
// The float test rounds each term of its exponent, so its boundary can move by a few ulp
// of the terms' sizes, which are at most ~4 kappa k2 with kappa = (a + c)^2 / (4 det)
// (1 for a circle); k2 is widened by 1% + 1e-4, far more than that for kappa <= 250.
// Beyond (needle-like Gaussians) or for anything not finite, no chord: the loops then
// cover the whole rectangle, as they would without these terms. tileData leaves the chords
// out (the values of "no chord"); tileChords adds them where they will be read.
template <typename T>
void tileData(const Projected<T>& P, int W, int H, TileGaussian<T>& q) {
  // Written field by field in place: built on the stack and copied, its 16-byte loads
  // waited on the narrower stores before them (a failed store forwarding: 40% of
  // projectAll's cycles in bench step).
  q.mx = P.mean2d[0];
  q.my = P.mean2d[1];
  q.a = P.conic[0];
  q.b = P.conic[1];
  q.c = P.conic[2];
  q.o = P.opacity;
  q.hx = P.half[0];
  q.hy = P.half[1];
  q.depth = P.depth;
  for (int k = 0; k < 3; ++k) q.col[k] = P.color[k];
  q.chord_slope = T(0);
  q.chord_k0 = std::numeric_limits<T>::max();
  q.chord_k1 = T(0);
  pixelSpan(P.mean2d[0], P.half[0], W, q.px0, q.px1);
  pixelSpan(P.mean2d[1], P.half[1], H, q.py0, q.py1);
}

template <typename T>
void tileChords(const Projected<T>& P, TileGaussian<T>& q) {
  const double a = P.conic[0], b = P.conic[1], c = P.conic[2], o = P.opacity;
  const double det = a * c - b * b;
  const double k2 = 2.0 * std::log(255.0 * o) * 1.01 + 1e-4;
  if (a > 0 && det > 0 && std::isfinite(a + b + c + det + k2) && (a + c) * (a + c) <= 1000.0 * det) {
    q.chord_slope = static_cast<T>(-b / a);
    q.chord_k0 = static_cast<T>(k2 / a);
    q.chord_k1 = static_cast<T>(det / (a * a));
  }
}

// Whether a Gaussian's alpha ellipse can reach a pixel centre of the tile [x0, x1) x
// [y0, y1): a pixel passes o G >= 1/255 only where q = a dx^2 + 2 b dx dy + c dy^2 <= k2 =
// 2 ln(255 o) (rule 7's threshold), so a tile is skipped when the minimum of q over the
// box of its pixel centres exceeds k2 widened as tileData's chords are (1% + 1e-4, which
// covers the float test's rounding for kappa <= 250; the widened k2 is chord_k0 * a).
// The minimum of a positive definite quadratic over a box is 0 when the box holds the
// mean, else it lies on an edge, where q is a parabola in one variable. Gaussians without
// chords (needle-like or not finite) are never skipped: the rectangle alone decides, as
// before. Only the list of pairs shrinks: a skipped pair is one no pixel of the tile
// would take, so images, walks and gradients are those of the rectangle's lists (tested
// against the reference).
template <typename T>
bool tileMeets(const TileGaussian<T>& g, int x0, int y0, int x1, int y1) {
  if (g.chord_k0 == std::numeric_limits<T>::max()) return true;
  const double a = g.a, b = g.b, c = g.c, k2 = static_cast<double>(g.chord_k0) * a;
  const double X0 = x0 + 0.5 - static_cast<double>(g.mx), X1 = x1 - 0.5 - static_cast<double>(g.mx);
  const double Y0 = y0 + 0.5 - static_cast<double>(g.my), Y1 = y1 - 0.5 - static_cast<double>(g.my);
  if (X0 <= 0 && 0 <= X1 && Y0 <= 0 && 0 <= Y1) return true;
  auto q = [&](double x, double y) { return a * x * x + 2.0 * b * x * y + c * y * y; };
  double m = q(X0, std::clamp(-b * X0 / c, Y0, Y1));
  m = std::min(m, q(X1, std::clamp(-b * X1 / c, Y0, Y1)));
  m = std::min(m, q(std::clamp(-b * Y0 / a, X0, X1), Y0));
  m = std::min(m, q(std::clamp(-b * Y1 / a, X0, X1), Y1));
  return m <= k2;
}

template <typename T>
void gatherTile(const RasterStateT<T>& st, int tile, std::vector<TileGaussian<T>>& out) {
  const std::uint32_t b = st.tile_start[tile], e = st.tile_start[tile + 1];
  reserveKept(out, e - b);  // per thread and kept (splat/kept_buffers.h)
  out.resize(e - b);
  // The entries are scattered over tile_data (depth order): their loads are fetched 24
  // entries ahead, both cache lines of each (an entry is 76 bytes). By perf samples at 100k
  // Gaussians, 8 or 48 ahead left more time here (docs/DECISIONS.md).
  constexpr std::uint32_t kAhead = 24;
  const TileGaussian<T>* data = st.tile_data.data();
  for (std::uint32_t k = b; k < e; ++k) {
    if (k + kAhead < e) {
      const char* next = reinterpret_cast<const char*>(data + st.entry_gauss[k + kAhead]);
      __builtin_prefetch(next);
      __builtin_prefetch(next + sizeof(TileGaussian<T>) - 1);
    }
    out[k - b] = data[st.entry_gauss[k]];
  }
}

// exp for x <= 0 in float without a libm call, so the pixel loops vectorise: Cody-Waite
// range reduction x = n ln2 + r, |r| <= ln2 / 2 + rounding, and a degree-6 polynomial
// (relative error < 3e-7 over the range). Below -87 it returns 0 (e^-87 ~ 1.6e-38 is
// far under every threshold of the contract). The double instantiation uses std::exp.
inline float expNonPositive(float x) {
  const float xc = std::max(x, -87.0f);
  const float t = xc * 1.4426950408889634f;
  const float n = static_cast<float>(static_cast<int>(t - 0.5f));  // t <= 0: rounds to nearest
  const float r = (xc - n * 0.693145751953125f) - n * 1.428606765330187e-06f;
  float p = 1.0f / 720.0f;
  p = p * r + 1.0f / 120.0f;
  p = p * r + 1.0f / 24.0f;
  p = p * r + 1.0f / 6.0f;
  p = p * r + 0.5f;
  p = p * r + 1.0f;
  p = p * r + 1.0f;
  const float scale = std::bit_cast<float>((static_cast<std::int32_t>(n) + 127) << 23);
  return x < -87.0f ? 0.0f : p * scale;
}
inline double expNonPositive(double x) { return std::exp(x); }

// The exponent of a Gaussian at offset (dx, dy), written once so that the forward and
// backward passes round identically (their threshold decisions must agree). The row
// terms are separate so the forward pass can hoist them out of its pixel loop.
template <typename T>
T rowQuad(const TileGaussian<T>& q, T dy) { return T(-0.5) * q.c * dy * dy; }
template <typename T>
T rowCross(const TileGaussian<T>& q, T dy) { return q.b * dy; }
template <typename T>
T powerAt(const TileGaussian<T>& q, T dx, T row_quad, T row_cross) {
  return T(-0.5) * q.a * dx * dx + row_quad - row_cross * dx;
}

// G and alpha of a Gaussian at a pixel centre; false when it does not touch the pixel
// (outside its rectangle, or alpha below 1/255). `unclamped`: o G < 0.99.
template <typename T>
bool evalAlpha(const TileGaussian<T>& q, T px, T py, T& dx, T& dy, T& G, T& alpha, bool& unclamped) {
  dx = px - q.mx;
  dy = py - q.my;
  if (std::abs(dx) > q.hx || std::abs(dy) > q.hy) return false;
  const T power = powerAt(q, dx, rowQuad(q, dy), rowCross(q, dy));
  if (power > 0) return false;  // cannot happen for a valid conic; guards rounding
  G = expNonPositive(power);
  const T oG = q.o * G;
  unclamped = oG < projection::Thresholds<T>::max_alpha;
  alpha = unclamped ? oG : projection::Thresholds<T>::max_alpha;
  return alpha >= projection::Thresholds<T>::min_alpha;
}

// The scratch of binAndSort and depthOrder, kept per thread between renders
// (splat/kept_buffers.h).
struct BinScratch {
  std::vector<std::uint32_t> slot_tile, order, key, key2, order2, chunk_fill;
};

// Rule 6 for every tile at once: the Gaussians with pairs, by camera z, ties by index.
// Binning them in this order (a stable counting sort by tile) leaves every tile sorted,
// which costs far less than sorting each tile. Float depths go through a stable LSD radix
// sort on their bits (mapped so that unsigned order is float order); double uses
// std::sort. The order goes to `sc.order`.
template <typename T>
void depthOrder(const std::vector<Projected<T>>& proj, const std::vector<std::uint32_t>& count, BinScratch& sc) {
  std::vector<std::uint32_t>& order = sc.order;
  order.clear();
  order.reserve(proj.size());
  for (std::size_t i = 0; i < proj.size(); ++i)
    if (count[i]) order.push_back(static_cast<std::uint32_t>(i));
  if constexpr (std::is_same_v<T, float>) {
    const std::size_t m = order.size();
    std::vector<std::uint32_t>& key = sc.key;
    std::vector<std::uint32_t>& key2 = sc.key2;
    std::vector<std::uint32_t>& order2 = sc.order2;
    key.resize(m);
    key2.resize(m);
    order2.resize(m);
    for (std::size_t j = 0; j < m; ++j) {
      // + 0 turns -0 into +0, which the comparison of rule 6 treats as equal.
      const std::uint32_t b = std::bit_cast<std::uint32_t>(proj[order[j]].depth + 0.0f);
      key[j] = (b & 0x80000000u) ? ~b : (b | 0x80000000u);
    }
    constexpr int kBits = 11, kBuckets = 1 << kBits;
    for (int shift = 0; shift < 32; shift += kBits) {
      std::array<std::uint32_t, kBuckets + 1> start{};
      for (std::size_t j = 0; j < m; ++j) ++start[((key[j] >> shift) & (kBuckets - 1)) + 1];
      for (int k = 0; k < kBuckets; ++k) start[k + 1] += start[k];
      for (std::size_t j = 0; j < m; ++j) {
        const std::uint32_t d = start[(key[j] >> shift) & (kBuckets - 1)]++;
        key2[d] = key[j];
        order2[d] = order[j];
      }
      key.swap(key2);
      order.swap(order2);
    }
  } else {
    std::sort(order.begin(), order.end(), [&](std::uint32_t x, std::uint32_t y) {
      return proj[x].depth < proj[y].depth || (proj[x].depth == proj[y].depth && x < y);
    });
  }
}

template <typename T>
void tilePixels(const RasterStateT<T>& st, int tile, int width, int height, int& x0, int& y0, int& x1,
                int& y1) {
  const int tx = tile % st.tiles_x, ty = tile / st.tiles_x;
  x0 = tx * kTileSize;
  y0 = ty * kTileSize;
  x1 = std::min(width, x0 + kTileSize);
  y1 = std::min(height, y0 + kTileSize);
}


// Columns or rows of a tile (offsets 0..15) whose pixel centres may lie within
// mean +- half: the exact test is applied per pixel, this only bounds the loops, so it
// is widened by a pixel against rounding.
template <typename T>
void tileSpan(T mean, T half, int origin, int limit, int& lo, int& hi) {
  lo = std::max(0, static_cast<int>(std::floor(mean - half - T(0.5))) - 1 - origin);
  hi = std::min(limit - origin - 1, static_cast<int>(std::ceil(mean + half - T(0.5))) + 1 - origin);
}

// Front-to-back compositing of one tile, Gaussian by Gaussian over the pixels of its
// rectangle, so the inner loop runs over contiguous pixels without branches. Each
// pixel sees exactly the per-pixel sequence of rule 7.
template <typename T>
void compositeTile(const std::vector<TileGaussian<T>>& q, int x0, int y0, int x1, int y1, const T bg[3],
                   int W, RenderOutputT<T>& out, RasterStateT<T>& st) {
  constexpr int P = kTileSize * kTileSize;
  alignas(64) T Tr[P], C0[P], C1[P], C2[P], D[P];
  alignas(64) std::int32_t walked[P], contrib[P], active[P];
  const int w = x1 - x0, h = y1 - y0;
  for (int k = 0; k < P; ++k) {
    Tr[k] = 1;
    C0[k] = C1[k] = C2[k] = D[k] = 0;
    walked[k] = contrib[k] = 0;
    active[k] = (k % kTileSize) < w && (k / kTileSize) < h;
  }
  int n_active = w * h;
  const std::int32_t nq = static_cast<std::int32_t>(q.size());
  for (std::int32_t j = 0; j < nq && n_active > 0; ++j) {
    const TileGaussian<T>& g = q[j];
    int c0, c1, r0, r1;
    tileSpan(g.mx, g.hx, x0, x1, c0, c1);
    tileSpan(g.my, g.hy, y0, y1, r0, r1);
    int stopped = 0;
    for (int r = r0; r <= r1; ++r) {
      const T dy = T(y0 + r) + T(0.5) - g.my;
      const bool row_in = std::abs(dy) <= g.hy;
      if (!row_in) continue;
      const T qy = rowQuad(g, dy);
      const T by = rowCross(g, dy);
      T* tr = Tr + r * kTileSize;
      T* c0p = C0 + r * kTileSize;
      T* c1p = C1 + r * kTileSize;
      T* c2p = C2 + r * kTileSize;
      T* dp = D + r * kTileSize;
      std::int32_t* wk = walked + r * kTileSize;
      std::int32_t* ct = contrib + r * kTileSize;
      std::int32_t* ac = active + r * kTileSize;
#pragma GCC ivdep
      for (int c = c0; c <= c1; ++c) {
        const T dx = T(x0 + c) + T(0.5) - g.mx;
        const T power = powerAt(g, dx, qy, by);
        const T G = expNonPositive(power < T(0) ? power : T(0));
        const T oG = g.o * G;
        const T alpha = oG < projection::Thresholds<T>::max_alpha ? oG : projection::Thresholds<T>::max_alpha;
        // Non-short-circuit '&' keeps the body branch-free so it vectorises.
        const bool ok = (ac[c] != 0) & (std::abs(dx) <= g.hx) & (power <= T(0)) & (alpha >= projection::Thresholds<T>::min_alpha);
        const T next = tr[c] * (T(1) - alpha);
        const bool stop = ok & (next < projection::Thresholds<T>::min_transmittance);
        const bool take = ok & !stop;
        const T wgt = take ? alpha * tr[c] : T(0);
        c0p[c] += wgt * g.col[0];
        c1p[c] += wgt * g.col[1];
        c2p[c] += wgt * g.col[2];
        dp[c] += wgt * g.depth;
        tr[c] = take ? next : tr[c];
        wk[c] = take ? j + 1 : wk[c];
        ct[c] += take ? 1 : 0;
        ac[c] = stop ? 0 : ac[c];
        stopped += stop ? 1 : 0;
      }
    }
    n_active -= stopped;
  }
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      const int k = r * kTileSize + c;
      const std::size_t pix = static_cast<std::size_t>(y0 + r) * W + (x0 + c);
      out.rgb[pix * 3] = C0[k] + Tr[k] * bg[0];
      out.rgb[pix * 3 + 1] = C1[k] + Tr[k] * bg[1];
      out.rgb[pix * 3 + 2] = C2[k] + Tr[k] * bg[2];
      out.alpha[pix] = T(1) - Tr[k];
      out.depth[pix] = (T(1) - Tr[k]) >= T(1e-6) ? D[k] / (T(1) - Tr[k]) : T(0);
      out.contributors[pix] = contrib[k];
      st.final_T[pix] = Tr[k];
      st.n_walked[pix] = static_cast<std::uint32_t>(walked[k]);
    }
}

}  // namespace

const char* rasterKernelName(const RasterExecution& e) {
  return kKernelSets[raster_execution::kernelIndex(e.kernels)].name;
}

namespace {

// The forward pass runs three stages: projectAll (rules 1-5, per Gaussian), binAndSort
// (rule 6, per tile) and compositeTiles (rule 7, per pixel).

// What projection leaves for binning: the tiles each projected Gaussian touches.
struct TileCover {
  std::vector<std::uint32_t> count;      // per Gaussian: tiles touched, 0 when culled
  std::vector<std::array<int, 4>> rect;  // per Gaussian: tiles x0, x1, y0, y1 (inclusive)
  // Per Gaussian whose rectangle has kMetMaskMin..kMetMaskMax tiles: the tiles its ellipse
  // meets, bit (ty - y0) * width + (tx - x0), so that binning lists them without testing
  // each again (the tests are double arithmetic per tile); unused for other rectangles.
  std::vector<std::uint64_t> met;
};
constexpr int kMetMaskMin = 5, kMetMaskMax = 64;

// Whether forEachTileMet tests rect's tiles with tileMeets (which reads the chords):
// up to 2x2 tiles the test costs more than the pairs it saves (bench step's small
// Gaussians: render 7% slower when every rectangle was tested), so all are kept.
inline bool tilesTested(const std::array<int, 4>& rect) {
  return (rect[1] - rect[0] + 1) * (rect[3] - rect[2] + 1) >= kMetMaskMin;
}

// Calls f(tx, ty) for the tiles of rect (tiles x0, x1, y0, y1, inclusive) that P's alpha
// ellipse meets (tileMeets), row by row: projection counts them and binning lists them
// with the same calls.
template <typename T, typename F>
void forEachTileMet(const TileGaussian<T>& g, const std::array<int, 4>& rect, int W, int H, F&& f) {
  const bool test = tilesTested(rect);
  for (int ty = rect[2]; ty <= rect[3]; ++ty)
    for (int tx = rect[0]; tx <= rect[1]; ++tx) {
      const int x0 = tx * kTileSize, y0 = ty * kTileSize;
      if (!test || tileMeets(g, x0, y0, std::min(W, x0 + kTileSize), std::min(H, y0 + kTileSize))) f(tx, ty);
    }
}

// The width in tiles of rect when TileCover::met holds its tiles (kMetMaskMin..kMetMaskMax
// tiles), else 0: the one test of coverTiles and forEachCoveredTile.
inline int metMaskWidth(const std::array<int, 4>& rect) {
  const int rw = rect[1] - rect[0] + 1, area = rw * (rect[3] - rect[2] + 1);
  return area >= kMetMaskMin && area <= kMetMaskMax ? rw : 0;
}

// The tiles of rect that g's alpha ellipse meets, for binning (forEachCoveredTile): their
// count, and their mask where rect suits one (TileCover::met).
template <typename T>
std::uint32_t coverTiles(const TileGaussian<T>& g, const std::array<int, 4>& rect, int W, int H,
                         std::uint64_t& met) {
  const int rw = metMaskWidth(rect);
  if (rw == 0) {
    std::uint32_t count = 0;
    forEachTileMet(g, rect, W, H, [&](int, int) { ++count; });
    return count;
  }
  std::uint64_t m = 0;
  forEachTileMet(g, rect, W, H, [&](int tx, int ty) { m |= std::uint64_t{1} << ((ty - rect[2]) * rw + (tx - rect[0])); });
  met = m;
  return static_cast<std::uint32_t>(std::popcount(m));
}

// Calls f(tx, ty) for Gaussian i's tiles that coverTiles counted, in forEachTileMet's order
// (row by row; a mask's bits in increasing order are that order).
template <typename T, typename F>
void forEachCoveredTile(const TileCover& cover, std::size_t i, const TileGaussian<T>& g, int W, int H, F&& f) {
  const std::array<int, 4>& rect = cover.rect[i];
  const int rw = metMaskWidth(rect);
  if (rw == 0) {
    forEachTileMet(g, rect, W, H, f);
    return;
  }
  for (std::uint64_t m = cover.met[i]; m; m &= m - 1) {
    const int bit = std::countr_zero(m);
    f(rect[0] + bit % rw, rect[2] + bit / rw);
  }
}

// The projection kernels' view of a float model and camera (raster_kernels::ProjectIn).
raster_kernels::ProjectIn projectInput(const GaussiansT<float>& g, const CameraT<float>& cam,
                                       const RasterSettings& rs) {
  raster_kernels::ProjectIn in{};
  in.means = g.means.data();
  in.log_scales = g.log_scales.data();
  in.rotations = g.rotations.data();
  in.opacities = g.opacities.data();
  in.sh = g.sh.data();
  in.sh_stride = 3 * g.shCoeffs();
  in.sh_degree = rs.sh_degree;
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) in.R[r][k] = cam.R[r][k];
    in.t[r] = cam.t[r];
    in.center[r] = cam.center[r];
  }
  in.fx = cam.fx;
  in.fy = cam.fy;
  in.cx = cam.cx;
  in.cy = cam.cy;
  in.width = static_cast<float>(cam.width);
  in.height = static_cast<float>(cam.height);
  in.gx_mid = cam.gx_mid;
  in.gx_half = cam.gx_half;
  in.gy_mid = cam.gy_mid;
  in.gy_half = cam.gy_half;
  in.near_plane = static_cast<float>(rs.near_plane);
  in.eps2d = static_cast<float>(rs.eps2d);
  return in;
}

// One Gaussian range of projectAll's projection (without its tile work).
void projectRangeWith(const GaussiansT<float>& g, const CameraT<float>& camT, const RasterSettings& rs, int isa,
                      std::size_t begin, std::size_t end, Projected<float>* out) {
  if (rs.extent == ExtentRule::kOpacityAware) {
    kKernelSets[isa].project(projectInput(g, camT, rs), begin, end, out);
    return;
  }
  for (std::size_t i = begin; i < end; ++i) out[i] = projection::project(g, i, camT, rs);
}

// Projects every unmasked Gaussian, culls, fills its tile data, radius and visibility,
// and counts the tiles its pixel rectangle touches.
// `cover` is the caller's (kept between renders: rasterizeIntoT).
template <typename T>
void projectAll(const GaussiansT<T>& g, const CameraT<T>& camT, std::span<const std::uint8_t> mask, int W,
                int H, RasterStateT<T>& st, RenderOutputT<T>& out, TileCover& cover) {
  const std::size_t n = g.size();
  const RasterSettings& rs = st.settings;
  out.radii.assign(n, T(0));
  out.visible.assign(n, 0);
  st.proj.resize(n);
  st.tile_data.resize(n);
  cover.count.assign(n, 0);
  cover.rect.resize(n);
  cover.met.resize(n);
  arena(st).execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const auto& r) {
      const FloatEnvGuard fenv;  // geometry/float_env.h
      // Float: the SIMD projection of the render's kernel set, bit for bit project()'s
      // (ProjectKernels.*); masked Gaussians are projected and then cleared.
      if constexpr (std::is_same_v<T, float>) projectRangeWith(g, camT, rs, st.isa, r.begin(), r.end(), st.proj.data());
      for (std::size_t i = r.begin(); i < r.end(); ++i) {
        if (!mask.empty() && !mask[i]) {
          st.proj[i] = Projected<T>{};
          continue;
        }
        if constexpr (!std::is_same_v<T, float>) st.proj[i] = projection::project(g, i, camT, rs);
        Projected<T>& P = st.proj[i];
        if (!P.visible) continue;
        tileData(P, W, H, st.tile_data[i]);
        out.visible[i] = 1;
        out.radii[i] = P.radius;
        int px0, px1, py0, py1;
        pixelRange(P.mean2d[0], P.half[0], W, px0, px1);
        pixelRange(P.mean2d[1], P.half[1], H, py0, py1);
        if (px0 > px1 || py0 > py1) continue;
        std::array<int, 4>& rect = cover.rect[i];
        rect = {px0 / kTileSize, px1 / kTileSize, py0 / kTileSize, py1 / kTileSize};
        // The chords are read by the kernels' block-row bounds (wide Gaussians) and by
        // tileMeets, and by nothing else: most Gaussians of a large model skip their
        // double logarithm and divisions.
        TileGaussian<T>& q = st.tile_data[i];
        if (q.px1 - q.px0 + 1 > kChordMinSpan || tilesTested(rect)) tileChords(P, q);
        cover.count[i] = coverTiles(q, rect, W, H, cover.met[i]);
      }
    });
  });
}

// Builds the per-tile lists: pair slots, Gaussian-major, then a stable counting sort by
// tile of the Gaussians in depth order (depthOrder), so each tile comes out sorted by
// rule 6.
template <typename T>
void binAndSort(const TileCover& cover, int W, int H, RasterStateT<T>& st) {
  const std::size_t n = cover.count.size();
  const int tiles = st.tiles_x * st.tiles_y;
  st.gauss_start.assign(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) st.gauss_start[i + 1] = st.gauss_start[i] + cover.count[i];
  const std::uint32_t pairs = st.gauss_start[n];
  KeptBuffers<BinScratch> kept;
  BinScratch& sc = kept.get();
  std::vector<std::uint32_t>& slot_tile = sc.slot_tile;
  assignKept(slot_tile, pairs, 0u);
  arena(st).execute([&] {
    // The pairs' tiles and the depth order (serial) do not depend on each other.
    tbb::parallel_invoke([&] {
                           const FloatEnvGuard fenv;  // geometry/float_env.h (depths are floats)
                           depthOrder(st.proj, cover.count, sc);
                         },
                         [&] {
                           tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const auto& r) {
                             const FloatEnvGuard fenv;  // geometry/float_env.h
                             for (std::size_t i = r.begin(); i < r.end(); ++i) {
                               if (!cover.count[i]) continue;
                               std::uint32_t k = st.gauss_start[i];
                               forEachCoveredTile(cover, i, st.tile_data[i], W, H, [&](int tx, int ty) {
                                 slot_tile[k++] = static_cast<std::uint32_t>(ty * st.tiles_x + tx);
                               });
                             }
                           });
                         });
  });
  // A stable counting sort of the pairs by tile, the Gaussians taken in depth order, in
  // parallel: the depth order is cut into chunks, each chunk counts its pairs per tile,
  // and each chunk's pairs go to its tile after those of the chunks before it, which is
  // where the serial loop put them (the same lists for any number of chunks or threads).
  const std::vector<std::uint32_t>& order = sc.order;
  const std::size_t m = order.size();
  const std::size_t chunks = std::clamp<std::size_t>(m / 2048, 1, 16);
  auto chunkRange = [&](std::size_t c) { return std::pair{c * m / chunks, (c + 1) * m / chunks}; };
  const std::size_t nt = static_cast<std::size_t>(tiles);
  std::vector<std::uint32_t>& cf = sc.chunk_fill;
  assignKept(cf, chunks * nt, 0u);
  auto forChunks = [&](auto&& body) {
    arena(st).execute([&] {
      tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
        const FloatEnvGuard fenv;  // geometry/float_env.h (integers only, but every task body has one)
        const auto [b, e] = chunkRange(c);
        body(c, b, e);
      });
    });
  };
  forChunks([&](std::size_t c, std::size_t b, std::size_t e) {
    std::uint32_t* cnt = cf.data() + c * nt;
    for (std::size_t j = b; j < e; ++j) {
      const std::uint32_t i = order[j];
      for (std::uint32_t k = st.gauss_start[i]; k < st.gauss_start[i + 1]; ++k) ++cnt[slot_tile[k]];
    }
  });
  // Counts to starts: the tile's start, then each chunk's place within the tile.
  st.tile_start.assign(nt + 1, 0);
  std::uint32_t at = 0;
  for (std::size_t t = 0; t < nt; ++t) {
    st.tile_start[t] = at;
    for (std::size_t c = 0; c < chunks; ++c) {
      const std::uint32_t k = cf[c * nt + t];
      cf[c * nt + t] = at;
      at += k;
    }
  }
  st.tile_start[nt] = at;
  st.entry_gauss.resize(pairs);
  st.pair_entry.resize(pairs);
  forChunks([&](std::size_t c, std::size_t b, std::size_t e) {
    std::uint32_t* fill = cf.data() + c * nt;
    for (std::size_t j = b; j < e; ++j) {
      const std::uint32_t i = order[j];
      for (std::uint32_t k = st.gauss_start[i]; k < st.gauss_start[i + 1]; ++k) {
        const std::uint32_t en = fill[slot_tile[k]]++;
        st.entry_gauss[en] = i;
        st.pair_entry[k] = en;
      }
    }
  });
}

// A float render's images, sized, not cleared: the float kernels write every value of
// every pixel of every tile (ForwardState::write), and clearing the images first cost a
// serial memset of 32 bytes a pixel (6 MB at 512x384) every render. Depth and
// contributors are left empty unless asked for (RasterSettings::depth_and_contributors).
void allocateImages(int W, int H, bool depth_and_contributors, RenderOutputT<float>& out) {
  out.width = W;
  out.height = H;
  const std::size_t P = static_cast<std::size_t>(W) * H;
  out.rgb.resize(P * 3);
  out.alpha.resize(P);
  out.depth.resize(depth_and_contributors ? P : 0);
  out.contributors.resize(depth_and_contributors ? P : 0);
}

// The kernels' view of a render's images (depth and contributors null when left out).
raster_kernels::ForwardOut forwardOut(int W, RenderOutputT<float>& out, float* final_T, std::uint32_t* n_walked) {
  const bool aux = !out.depth.empty();
  return {W, out.rgb.data(), out.alpha.data(), aux ? out.depth.data() : nullptr,
          aux ? out.contributors.data() : nullptr, final_T, n_walked};
}

// Composites every tile front to back (float: the SIMD kernels of st.isa) into `out`,
// keeping each pixel's final transmittance and walk length for the backward pass.
template <typename T>
void compositeTiles(int W, int H, RasterStateT<T>& st, RenderOutputT<T>& out) {
  const std::size_t P = static_cast<std::size_t>(W) * H;
  if constexpr (std::is_same_v<T, float>) {
    allocateImages(W, H, st.settings.depth_and_contributors, out);
    st.final_T.resize(P);
    st.n_walked.resize(P);
  } else {
    out.rgb.assign(P * 3, T(0));
    out.alpha.assign(P, T(0));
    out.depth.assign(P, T(0));
    out.contributors.assign(P, 0);
    st.final_T.assign(P, T(1));
    st.n_walked.assign(P, 0);
  }
  const RasterSettings& rs = st.settings;
  const T bg[3] = {T(rs.background[0]), T(rs.background[1]), T(rs.background[2])};
  arena(st).execute([&] {
    tbb::parallel_for(0, st.tiles_x * st.tiles_y, [&](int tile) {
      const FloatEnvGuard fenv;  // geometry/float_env.h
      thread_local std::vector<TileGaussian<T>> q;
      gatherTile(st, tile, q);
      int x0, y0, x1, y1;
      tilePixels(st, tile, W, H, x0, y0, x1, y1);
      if constexpr (std::is_same_v<T, float>) {
        const raster_kernels::ForwardOut fo = forwardOut(W, out, st.final_T.data(), st.n_walked.data());
        kKernelSets[st.isa].composite(q.data(), static_cast<int>(q.size()), x0, y0, x1, y1, bg, fo);
      } else {
        compositeTile(q, x0, y0, x1, y1, bg, W, out, st);
      }
    });
  });
  if constexpr (!std::is_same_v<T, float>) {
    // The generic path computes them all the same (it serves tests, not training).
    if (!rs.depth_and_contributors) {
      out.depth.clear();
      out.contributors.clear();
    }
  }
}

}  // namespace

namespace {

// The state a render keeps for its backward pass, taken from `held` when nothing else
// shares it (its buffers are then refilled without allocating), otherwise new. `held`
// is left empty either way.
template <typename S>
std::shared_ptr<S> reuseOrMake(std::shared_ptr<const S>& held) {
  std::shared_ptr<const S> h = std::move(held);
  if (h && h.use_count() == 1) return std::const_pointer_cast<S>(std::move(h));
  return std::make_shared<S>();
}

// Settings, kernels and tile grid of a render (the first lines of every forward pass).
template <typename T>
void beginState(RasterStateT<T>& st, const RasterSettings& s, int max_sh_degree, int W, int H) {
  st.settings = s;
  st.isa = raster_execution::kernelIndex(s.execution.kernels);
  st.settings.sh_degree = std::clamp(s.sh_degree, 0, max_sh_degree);
  st.tiles_x = (W + kTileSize - 1) / kTileSize;
  st.tiles_y = (H + kTileSize - 1) / kTileSize;
}

}  // namespace

// The forward pass into `out`, whose buffers (and state, when unshared) are reused: every
// array is refilled with assign/resize, so the result is the same as into an empty
// output, and no allocation happens once `out` has held a render at least this large.
template <typename T>
void rasterizeIntoT(const GaussiansT<T>& g, const Camera& cam, const RasterSettings& s,
                    std::span<const std::uint8_t> mask, RenderOutputT<T>& out) {
  const int W = cam.K.width, H = cam.K.height;
  std::shared_ptr<RasterStateT<T>> st = reuseOrMake(out.state);
  beginState(*st, s, g.max_sh_degree, W, H);
  const CameraT<T> camT(cam, T(s.guard_band));

  out.width = W;
  out.height = H;
  KeptBuffers<TileCover> kept_cover;
  TileCover& cover = kept_cover.get();
  projectAll(g, camT, mask, W, H, *st, out, cover);
  binAndSort(cover, W, H, *st);
  compositeTiles(W, H, *st, out);
  out.state = std::move(st);
}

void projectRangeFloat(const GaussiansT<float>& g, const Camera& cam, const RasterSettings& s, std::size_t begin,
                       std::size_t end, std::vector<projection::Projected<float>>& out) {
  if (begin > end || end > g.size()) throw std::invalid_argument("projectRangeFloat: range beyond the model");
  RasterStateT<float> st;
  beginState(st, s, g.max_sh_degree, cam.K.width, cam.K.height);
  const CameraT<float> camT(cam, s.guard_band);
  out.resize(g.size());
  const FloatEnvGuard fenv;
  projectRangeWith(g, camT, st.settings, st.isa, begin, end, out.data());
}

namespace {
// The tests' entries to the per-Gaussian kernels: one gradient entry per listed Gaussian,
// arrays of the model's sizes, indices inside it.
void checkChainInputs(const Gaussians& g, const std::vector<std::uint32_t>& idx, std::size_t per_listed,
                      const std::vector<Projected<float>>& proj, const Gaussians& out, const char* who) {
  if (idx.size() != per_listed || proj.size() != g.size() || out.size() != g.size() ||
      out.shCoeffs() != g.shCoeffs())
    throw std::invalid_argument(std::string(who) + ": sizes disagree");
  for (const std::uint32_t i : idx)
    if (i >= g.size()) throw std::invalid_argument(std::string(who) + ": index beyond the model");
}
}  // namespace

void projectBackwardFloat(const GaussiansT<float>& g, const Camera& cam, const RasterSettings& s,
                          const std::vector<std::uint32_t>& idx, const std::vector<Projected<float>>& proj,
                          const std::vector<ProjectedGrad<float>>& dP, GaussiansT<float>& grad) {
  checkChainInputs(g, idx, dP.size(), proj, grad, "projectBackwardFloat");
  RasterStateT<float> st;
  beginState(st, s, g.max_sh_degree, cam.K.width, cam.K.height);
  const CameraT<float> camT(cam, s.guard_band);
  const FloatEnvGuard fenv;
  kKernelSets[st.isa].project_backward(projectInput(g, camT, st.settings), idx.data(), static_cast<int>(idx.size()),
                                       proj.data(), dP.data(),
                                       {grad.means.data(), grad.log_scales.data(), grad.rotations.data(),
                                        grad.opacities.data(), grad.sh.data()});
}

template <typename T>
RenderOutputT<T> rasterizeT(const GaussiansT<T>& g, const Camera& cam, const RasterSettings& s,
                            std::span<const std::uint8_t> mask) {
  RenderOutputT<T> out;
  rasterizeIntoT(g, cam, s, mask, out);
  return out;
}

// --- The full render and a subset render in one pass (rasterizeWithSubset) -----------
// Kept apart from the single-render code above; it reuses its stages (projectAll,
// binAndSort) and differs only in the tile walks, which run the pair kernels
// (splat/raster/raster_kernels_pair_impl.h).

struct SubsetRasterState {
  std::vector<std::uint8_t> mask;              // per Gaussian, as given
  std::vector<std::uint8_t> entry_in_subset;   // per full tile entry: its Gaussian's mask
  std::vector<float> final_T;                  // per pixel, of the subset render
  std::vector<std::uint32_t> n_walked;         // per pixel: full-list entries walked
};

namespace {

// The backward's slot per (tile, Gaussian) pair: opacity, mean2d (2), conic (3), colour (3).
constexpr int kGradSlot = 9;

// The float backward kernels' slots, kept per thread between calls (splat/kept_buffers.h:
// a call nested in a TBB wait gets its own) and shared by the single and the pair
// backward. They are the largest buffer of a step: allocating them afresh every step made
// the allocator hand the memory back and fault it in again each time (about 13 MB of page
// faults per 512x384 residual step, more than the loss itself costs). Not cleared: the
// kernels write every slot.
struct GradSlots {
  std::vector<float> v;
};

float* keptGradSlots(KeptBuffers<GradSlots>& kept, std::uint32_t pairs) {
  std::vector<float>& v = kept.get().v;
  reserveKept(v, static_cast<std::size_t>(pairs) * kGradSlot);
  v.resize(static_cast<std::size_t>(pairs) * kGradSlot);
  return v.data();
}

// Pair k's slot of `count` values in a tile-ordered slot buffer, with the slot of pair
// k + 32 fetched ahead (both of its ends): the per-Gaussian reductions read the slots in
// pair order, which scatters over the buffer. `pairs` bounds the lookahead.
template <typename T>
inline const T* pairSlot(const RasterStateT<T>& st, const T* slots, std::uint32_t k, int count,
                         std::uint32_t pairs) {
  constexpr std::uint32_t kAhead = 32;
  if (k + kAhead < pairs) {
    const T* next = &slots[static_cast<std::size_t>(st.pair_entry[k + kAhead]) * count];
    __builtin_prefetch(next);
    __builtin_prefetch(reinterpret_cast<const char*>(next + count) - 1);
  }
  return &slots[static_cast<std::size_t>(st.pair_entry[k]) * count];
}

// The Gaussians of [begin, end) that have tile pairs, listed up to kChunk at a time: for
// each, add(i, k) sums its pair slots into the caller's k-th entry, and every full or last
// list goes to flush(list, count), the kernel set's SIMD stage. Shared by the backward's
// chain (chainSlots) and the Fisher pass's (squaredGradientsFloat).
template <std::size_t kChunk, typename Add, typename Flush>
void forListedGaussians(const std::vector<std::uint32_t>& gauss_start, std::size_t begin, std::size_t end, Add&& add,
                        Flush&& flush) {
  std::uint32_t list[kChunk];
  for (std::size_t b = begin; b < end; b += kChunk) {
    const std::size_t e = std::min(end, b + kChunk);
    int listed = 0;
    for (std::size_t i = b; i < e; ++i) {
      if (gauss_start[i] == gauss_start[i + 1]) continue;
      add(i, listed);
      list[listed++] = static_cast<std::uint32_t>(i);
    }
    if (listed) flush(list, listed);
  }
}

// The backward's last stage, shared by the single and the pair backward: each Gaussian's
// pair slots reduced in slot order, its 2D-mean gradient added to grad_mean2d
// (densification's statistic), and the sum chained to its parameters (projectBackward).
template <typename T>
void chainSlots(const GaussiansT<T>& g, const Camera& cam, const RasterStateT<T>& st, const T* slots,
                GaussiansT<T>& grad, std::vector<T>* grad_mean2d) {
  constexpr int kSlot = kGradSlot;
  const RasterSettings& rs = st.settings;
  const std::size_t n = g.size();
  const std::uint32_t end_pair = st.gauss_start[n];
  arena(st).execute([&] {
    const CameraT<T> camT(cam, T(rs.guard_band));
    // Float: the Gaussians that have pairs are listed, up to kChunk at a time, with their
    // summed gradients and chained by the kernel set's SIMD projectBackward (bit for bit
    // the scalar one: ProjectKernels.*).
    constexpr std::size_t kChunk = 256;
    [[maybe_unused]] raster_kernels::ProjectIn pin{};
    [[maybe_unused]] raster_kernels::ProjectGradOut pout{};
    if constexpr (std::is_same_v<T, float>) {
      pin = projectInput(g, camT, rs);
      pout = {grad.means.data(), grad.log_scales.data(), grad.rotations.data(), grad.opacities.data(),
              grad.sh.data()};
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kChunk), [&](const auto& r) {
      const FloatEnvGuard fenv;  // geometry/float_env.h
      [[maybe_unused]] ProjectedGrad<T> list_dP[kChunk];
      // A range may be longer than the grain: at most kChunk Gaussians per list.
      forListedGaussians<kChunk>(
          st.gauss_start, r.begin(), r.end(),
          [&](std::size_t i, int k) {
            ProjectedGrad<T> dP;
            for (std::uint32_t s = st.gauss_start[i]; s < st.gauss_start[i + 1]; ++s) {
              const T* sl = pairSlot(st, slots, s, kSlot, end_pair);
              dP.opacity += sl[0];
              dP.mean2d[0] += sl[1];
              dP.mean2d[1] += sl[2];
              for (int c = 0; c < 3; ++c) dP.conic[c] += sl[3 + c];
              for (int c = 0; c < 3; ++c) dP.color[c] += sl[6 + c];
            }
            if (grad_mean2d) {
              (*grad_mean2d)[2 * i] += dP.mean2d[0];
              (*grad_mean2d)[2 * i + 1] += dP.mean2d[1];
            }
            if constexpr (std::is_same_v<T, float>)
              list_dP[k] = dP;
            else
              projection::projectBackward(g, i, camT, rs, st.proj[i], dP, projection::ParamGradRef<T>::of(grad, i));
          },
          [&]([[maybe_unused]] const std::uint32_t* list, [[maybe_unused]] int listed) {
            if constexpr (std::is_same_v<T, float>)
              kKernelSets[st.isa].project_backward(pin, list, listed, st.proj.data(), list_dP, pout);
          });
    });
  });
}

struct PairKernelSet {
  raster_kernels::CompositePairFn composite;
  raster_kernels::BackwardPairFn backward;
};
// Indexed like kKernelSets (raster_execution::kernelIndex).
constexpr PairKernelSet kPairKernelSets[] = {
    {raster_kernels::base4::compositeTilePair, raster_kernels::base4::backwardTilePair},
    {raster_kernels::avx2::compositeTilePair, raster_kernels::avx2::backwardTilePair},
    // avx512: both on 32 registers (raster_kernels_avx512.cpp).
    {raster_kernels::avx512::compositeTilePair, raster_kernels::avx512::backwardTilePair},
};

// The public result of a float render (rasterize() and rasterizeWithSubset()), moved
// into `r` (no copy, no allocation).
void toRenderResult(RenderOutputT<float>&& o, RenderResult& r) {
  r.rgb.width = r.alpha.width = o.width;
  r.rgb.height = r.alpha.height = o.height;
  // 0 x 0 when the render left it out (RasterSettings::depth_and_contributors).
  r.depth.width = o.depth.empty() ? 0 : o.width;
  r.depth.height = o.depth.empty() ? 0 : o.height;
  r.rgb.channels = 3;
  r.alpha.channels = r.depth.channels = 1;
  r.rgb.data = std::move(o.rgb);
  r.alpha.data = std::move(o.alpha);
  r.depth.data = std::move(o.depth);
  r.contributors = std::move(o.contributors);
  r.radii = std::move(o.radii);
  r.visible = std::move(o.visible);
  r.state = std::move(o.state);
}
RenderResult toRenderResult(RenderOutputT<float>&& o) {
  RenderResult r;
  toRenderResult(std::move(o), r);
  return r;
}

// The buffers of a public result handed back to the templated passes (moved, so `r`'s
// vectors keep their capacity for the next render).
RenderOutputT<float> fromRenderResult(RenderResult& r) {
  RenderOutputT<float> o;
  o.width = r.rgb.width;
  o.height = r.rgb.height;
  o.rgb = std::move(r.rgb.data);
  o.alpha = std::move(r.alpha.data);
  o.depth = std::move(r.depth.data);
  o.contributors = std::move(r.contributors);
  o.radii = std::move(r.radii);
  o.visible = std::move(r.visible);
  o.state = std::move(r.state);
  return o;
}

}  // namespace

void rasterizeWithSubset(const Gaussians& g, const Camera& cam, const RasterSettings& s,
                         std::span<const std::uint8_t> mask, RenderPair& into) {
  if (mask.size() != g.size())
    throw std::invalid_argument("rasterizeWithSubset: the mask needs one byte per Gaussian");
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
  for (std::size_t e = 0; e < st->entry_gauss.size(); ++e)
    ss->entry_in_subset[e] = mask[st->entry_gauss[e]] != 0;
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
  const raster_kernels::CompositePairFn kernel = kPairKernelSets[st->isa].composite;
  arena(*st).execute([&] {
    tbb::parallel_for(0, st->tiles_x * st->tiles_y, [&](int tile) {
      const FloatEnvGuard fenv;  // geometry/float_env.h
      thread_local std::vector<TileGaussian<float>> q;
      gatherTile(*st, tile, q);
      int x0, y0, x1, y1;
      tilePixels(*st, tile, W, H, x0, y0, x1, y1);
      kernel(q.data(), ss->entry_in_subset.data() + st->tile_start[tile], static_cast<int>(q.size()), x0, y0, x1,
             y1, bg, fo_full, fo_sub);
    });
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

void rasterizeBackwardWithSubset(const Gaussians& g, const Camera& cam, const RasterSettings& s,
                                 const RenderPair& fwd, const ImageF& dL_drgb_full,
                                 const ImageF& dL_drgb_subset, Gaussians& grad,
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
  const raster_kernels::BackwardPairFn kernel = kPairKernelSets[st.isa].backward;
  arena(st).execute([&] {
    tbb::parallel_for(0, st.tiles_x * st.tiles_y, [&](int tile) {
      const FloatEnvGuard fenv;  // geometry/float_env.h
      thread_local std::vector<TileGaussian<float>> q;
      gatherTile(st, tile, q);
      if (q.empty()) return;
      int x0, y0, x1, y1;
      tilePixels(st, tile, W, H, x0, y0, x1, y1);
      const std::uint32_t b = st.tile_start[tile];
      kernel(q.data(), ss.entry_in_subset.data() + b, static_cast<int>(q.size()), x0, y0, x1, y1, bg, in_full,
             in_sub, slots_p + static_cast<std::size_t>(b) * kGradSlot);
    });
  });

  // The slots hold both branches' sums, so each Gaussian is chained once. The chain rule
  // (projectBackward) is linear in the projected gradients and costs about as much per
  // Gaussian as its whole walk, so one call instead of one per branch saves ~7 ms of a
  // 256x192, 40k step; the price is rounding: the parameters get chain(full + subset)
  // instead of chain(full) + chain(subset). grad_mean2d gets both branches' 2D-mean
  // gradients, as the two separate passes would add them.
  chainSlots(g, cam, st, slots_p, grad, grad_mean2d);
}

namespace {

// Walks one pixel's contributors back to front and calls
// visit(entry, dx, dy, G, alpha, unclamped, dL_dalpha, dL_dcolor_weight) where dL_dalpha
// is for the per-pixel objective sum_c w_c C_c and dL_dcolor_weight = alpha T.
template <typename T, typename Visit>
void walkBack(const std::vector<TileGaussian<T>>& q, std::uint32_t walked, T final_T, T px, T py,
              const T w[3], const T bg[3], Visit&& visit) {
  T Tr = final_T;
  T accum[3] = {0, 0, 0}, last_alpha = 0, last_col[3] = {0, 0, 0};
  const T bg_dot = bg[0] * w[0] + bg[1] * w[1] + bg[2] * w[2];
  for (std::uint32_t jj = walked; jj-- > 0;) {
    T dx, dy, G, alpha;
    bool unclamped;
    if (!evalAlpha(q[jj], px, py, dx, dy, G, alpha, unclamped)) continue;
    Tr = Tr / (T(1) - alpha);  // transmittance in front of this Gaussian
    T dL_dalpha = 0;
    for (int c = 0; c < 3; ++c) {
      accum[c] = last_alpha * last_col[c] + (T(1) - last_alpha) * accum[c];
      dL_dalpha += (q[jj].col[c] - accum[c]) * w[c];
    }
    dL_dalpha = dL_dalpha * Tr - final_T / (T(1) - alpha) * bg_dot;
    last_alpha = alpha;
    for (int c = 0; c < 3; ++c) last_col[c] = q[jj].col[c];
    visit(jj, dx, dy, G, alpha, unclamped, dL_dalpha, alpha * Tr);
  }
}

// The 2D gradients of one contribution: through alpha = o G (when unclamped) to the
// opacity, the 2D mean and the conic.
template <typename T>
void alphaToProjected(const TileGaussian<T>& q, T dx, T dy, T G, bool unclamped, T dL_dalpha, T* g2d) {
  if (!unclamped) return;
  g2d[0] += G * dL_dalpha;  // opacity
  const T dG = q.o * dL_dalpha * G;  // dL/dpower
  g2d[1] += dG * (q.a * dx + q.b * dy);  // mean2d x (d power / d mean = -d power / d dx)
  g2d[2] += dG * (q.b * dx + q.c * dy);
  g2d[3] += dG * T(-0.5) * dx * dx;  // conic a
  g2d[4] += dG * (-dx * dy);         // conic b
  g2d[5] += dG * T(-0.5) * dy * dy;  // conic c
}

// Walks every pixel's contributors back to front, tiles in parallel, for the per-pixel
// objective sum_c w_c C_c with w = weights(pixel), and calls
// visit(tile entry, its Gaussian's tile data, dx, dy, G, unclamped, dL/dalpha, alpha T, w).
template <typename T, typename Weights, typename Visit>
void walkAllPixels(const RasterStateT<T>& st, int W, int H, Weights&& weights, Visit&& visit) {
  const RasterSettings& rs = st.settings;
  const T bg[3] = {T(rs.background[0]), T(rs.background[1]), T(rs.background[2])};
  arena(st).execute([&] {
    tbb::parallel_for(0, st.tiles_x * st.tiles_y, [&](int tile) {
      const FloatEnvGuard fenv;  // geometry/float_env.h
      std::vector<TileGaussian<T>> q;
      gatherTile(st, tile, q);
      const std::uint32_t base = st.tile_start[tile];
      int x0, y0, x1, y1;
      tilePixels(st, tile, W, H, x0, y0, x1, y1);
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
          const std::size_t pix = static_cast<std::size_t>(y) * W + x;
          const T* w = weights(pix);
          walkBack(q, st.n_walked[pix], st.final_T[pix], T(x) + T(0.5), T(y) + T(0.5), w, bg,
                   [&](std::uint32_t jj, T dx, T dy, T G, T, bool unclamped, T dL_dalpha, T wcol) {
                     visit(base + jj, q[jj], dx, dy, G, unclamped, dL_dalpha, wcol, w);
                   });
        }
    });
  });
}

}  // namespace

// Fills the backward pass's per-pair slots (9 per pair: opacity, mean2d 2, conic 3,
// colour 3). The generic version walks pixel by pixel (the double tests run it); the
// float version below is the SIMD kernel with the same arithmetic per contribution.
template <typename T>
void backwardSlots(const RasterStateT<T>& st, int W, int H, const T* dL_drgb, T* slots) {
  constexpr int kSlot = kGradSlot;
  walkAllPixels(
      st, W, H, [&](std::size_t pix) { return &dL_drgb[pix * 3]; },
      [&](std::uint32_t e, const TileGaussian<T>& q, T dx, T dy, T G, bool unclamped, T dL_dalpha, T wcol,
          const T* w) {
        T* sl = &slots[static_cast<std::size_t>(e) * kSlot];
        alphaToProjected(q, dx, dy, G, unclamped, dL_dalpha, sl);
        for (int c = 0; c < 3; ++c) sl[6 + c] += wcol * w[c];
      });
}

// The float version runs the SIMD kernels of the instruction set the forward pass used.
template <>
void backwardSlots<float>(const RasterStateT<float>& st, int W, int H, const float* dL_drgb, float* slots) {
  const RasterSettings& rs = st.settings;
  const float bg[3] = {rs.background[0], rs.background[1], rs.background[2]};
  const raster_kernels::BackwardIn in{W, st.final_T.data(), st.n_walked.data(), dL_drgb};
  const raster_kernels::BackwardFn kernel = kKernelSets[st.isa].backward;
  arena(st).execute([&] {
    tbb::parallel_for(0, st.tiles_x * st.tiles_y, [&](int tile) {
      const FloatEnvGuard fenv;  // geometry/float_env.h
      thread_local std::vector<TileGaussian<float>> q;
      gatherTile(st, tile, q);
      if (q.empty()) return;
      int x0, y0, x1, y1;
      tilePixels(st, tile, W, H, x0, y0, x1, y1);
      kernel(q.data(), static_cast<int>(q.size()), x0, y0, x1, y1, bg, in,
             slots + static_cast<std::size_t>(st.tile_start[tile]) * kGradSlot);
    });
  });
}

template <typename T>
void rasterizeBackwardT(const GaussiansT<T>& g, const Camera& cam, const RasterSettings& s,
                        const RenderOutputT<T>& fwd, const T* dL_drgb, GaussiansT<T>& grad,
                        std::vector<T>* grad_mean2d) {
  const RasterStateT<T>& st = *fwd.state;
  const int W = fwd.width, H = fwd.height;
  const std::size_t n = g.size();
  const std::uint32_t pairs = st.gauss_start[n];
  // The float kernels write every slot, so they take the kept slots (keptGradSlots); the
  // generic walk adds into cleared slots.
  KeptBuffers<GradSlots> kept;
  std::vector<T> cleared;
  T* slots;
  if constexpr (std::is_same_v<T, float>) {
    slots = keptGradSlots(kept, pairs);
  } else {
    cleared.assign(static_cast<std::size_t>(pairs) * kGradSlot, T(0));
    slots = cleared.data();
  }
  backwardSlots(st, W, H, dL_drgb, slots);
  chainSlots(g, cam, st, slots, grad, grad_mean2d);
}

namespace {

// FisherRF's squared gradients in float: the SIMD tile kernels give per-pair moments
// (raster_kernels::FisherMoment), reduced per Gaussian in slot order, in double, and
// turned into squared parameter gradients with the Gaussian's Jacobian. Indexed like
// kKernelSets (raster_execution::kernelIndex).
constexpr raster_kernels::FisherFn kFisherKernels[] = {
    raster_kernels::base4::fisherTile, raster_kernels::avx2::fisherTile, raster_kernels::avx512::fisherTile};

// A slot buffer of at least `size` floats, not cleared, taken from a process-wide pool
// and given back when the lease ends. A fresh buffer per view (the selector runs one per
// candidate) cost its page faults and clearing, as much as the kernels' own work; the
// kernels write every pair's slot, so old contents never leak. A pool rather than one
// buffer per thread: a thread waiting inside a pass may run another pass's tasks.
class SlotLease {
 public:
  explicit SlotLease(std::size_t size) {
    {
      const std::lock_guard<std::mutex> lock(mutex());
      auto& pool = free();
      if (!pool.empty()) {
        buf_ = std::move(pool.back());
        pool.pop_back();
      }
    }
    if (buf_.size() < size) buf_.resize(size);
  }
  ~SlotLease() {
    const std::lock_guard<std::mutex> lock(mutex());
    free().push_back(std::move(buf_));
  }
  SlotLease(const SlotLease&) = delete;
  SlotLease& operator=(const SlotLease&) = delete;
  float* data() { return buf_.data(); }

 private:
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  static std::vector<std::vector<float>>& free() {
    static std::vector<std::vector<float>> pool;
    return pool;
  }
  std::vector<float> buf_;
};

void fisherMoments(const RasterStateT<float>& st, int W, int H, float* slots) {
  const RasterSettings& rs = st.settings;
  const float bg[3] = {rs.background[0], rs.background[1], rs.background[2]};
  const raster_kernels::FisherIn in{W, st.final_T.data(), st.n_walked.data()};
  const raster_kernels::FisherFn kernel = kFisherKernels[st.isa];
  arena(st).execute([&] {
    tbb::parallel_for(0, st.tiles_x * st.tiles_y, [&](int tile) {
      const FloatEnvGuard fenv;  // geometry/float_env.h
      thread_local std::vector<TileGaussian<float>> q;
      gatherTile(st, tile, q);
      if (q.empty()) return;
      int x0, y0, x1, y1;
      tilePixels(st, tile, W, H, x0, y0, x1, y1);
      kernel(q.data(), static_cast<int>(q.size()), x0, y0, x1, y1, bg, in,
             slots + static_cast<std::size_t>(st.tile_start[tile]) * raster_kernels::kFisherSlot);
    });
  });
}

// Per parameter p, the per-pixel gradient is o e u_p(dx, dy) + wc Jc_p with
//   u_p = (a dx + b dy) J_mx + (b dx + c dy) J_my - dx^2 J_ca / 2 - dx dy J_cb - dy^2 J_cc / 2
// (alphaToProjected's 2D gradients through the Jacobian), so its square summed over the
// pixels is a quadratic form in the moments: o^2 k^T E k + 2 o Jc k.F + Jc^2 W, with k
// the coefficients of (dx, dy, dx^2, dx dy, dy^2) in u_p.
void squaredGradientsFloat(const Gaussians& g, const Camera& cam, const RenderOutputT<float>& fwd,
                           Gaussians& sq) {
  using namespace raster_kernels;
  const RasterStateT<float>& st = *fwd.state;
  const RasterSettings& rs = st.settings;
  const std::size_t n = g.size();
  const std::uint32_t end_pair = st.gauss_start[n];
  SlotLease lease(static_cast<std::size_t>(end_pair) * kFisherSlot);
  float* const slots = lease.data();
  fisherMoments(st, fwd.width, fwd.height, slots);
  const CameraT<float> camT(cam, float(rs.guard_band));
  const ProjectIn pin = projectInput(g, camT, rs);
  const FisherGradOut out{sq.means.data(), sq.log_scales.data(), sq.opacities.data(), sq.sh.data()};
  arena(st).execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), [&](const auto& r) {
      const FloatEnvGuard fenv;  // geometry/float_env.h
      // The Gaussians with pairs, at most kChunk at a time, with their moments summed in
      // double in slot order, then the kernel set's SIMD chain (bit for bit
      // fisherChainReference: ProjectKernels.FisherChainEqualsReferenceBitForBit).
      constexpr std::size_t kChunk = 128;
      double mo[kChunk * kFisherSlot];
      forListedGaussians<kChunk>(
          st.gauss_start, r.begin(), r.end(),
          [&](std::size_t i, int k) {
            double* m = &mo[static_cast<std::size_t>(k) * kFisherSlot];
            std::fill(m, m + kFisherSlot, 0.0);
            for (std::uint32_t s = st.gauss_start[i]; s < st.gauss_start[i + 1]; ++s) {
              const float* sl = pairSlot(st, static_cast<const float*>(slots), s, kFisherSlot, end_pair);
              for (int p = 0; p < kFisherSlot; ++p) m[p] += sl[p];
            }
          },
          [&](const std::uint32_t* list, int listed) {
            kKernelSets[st.isa].fisher_chain(pin, list, listed, st.proj.data(), mo, out);
          });
    });
  });
}

}  // namespace

void fisherChainReference(const Gaussians& g, const Camera& cam, const RasterSettings& s, std::size_t i,
                          const Projected<float>& P, const double* mo, Gaussians& sq) {
  using namespace raster_kernels;
  RasterStateT<float> st;
  beginState(st, s, g.max_sh_degree, cam.K.width, cam.K.height);
  const RasterSettings& rs = st.settings;
  const CameraT<float> camT(cam, float(rs.guard_band));
  const FloatEnvGuard fenv;
  const int K = g.shCoeffs(), active = shCoeffCount(rs.sh_degree);
  // One frame for the Jacobian and the SH basis below.
  const projection::BackwardFrame<float> frame = projection::backwardFrame(g, i, camT, rs);
  float J[6][6];
  projection::projectJacobian(g, i, camT, rs, P, frame, J);
  const double a = P.conic[0], b = P.conic[1], c = P.conic[2], o = P.opacity;
  // The moments of the monomials (dx, dy, dx^2, dx dy, dy^2) pairwise.
  const double E[5][5] = {{mo[kE20], mo[kE11], mo[kE30], mo[kE21], mo[kE12]},
                          {mo[kE11], mo[kE02], mo[kE21], mo[kE12], mo[kE03]},
                          {mo[kE30], mo[kE21], mo[kE40], mo[kE31], mo[kE22]},
                          {mo[kE21], mo[kE12], mo[kE31], mo[kE22], mo[kE13]},
                          {mo[kE12], mo[kE03], mo[kE22], mo[kE13], mo[kE04]}};
  const double F[5] = {mo[kF10], mo[kF01], mo[kF20], mo[kF11], mo[kF02]};
  double out[6];
  for (int p = 0; p < 6; ++p) {
    const double k[5] = {a * J[0][p] + b * J[1][p], b * J[0][p] + c * J[1][p], -0.5 * J[2][p], -J[3][p],
                         -0.5 * J[4][p]};
    double quad = 0, lin = 0;
    for (int u = 0; u < 5; ++u) {
      double row = 0;
      for (int v = 0; v < 5; ++v) row += E[u][v] * k[v];
      quad += k[u] * row;
      lin += k[u] * F[u];
    }
    const double jc = J[5][p];
    // A sum of squares: a negative value can only be rounding of the expansion.
    out[p] = std::max(0.0, o * o * quad + 2.0 * o * jc * lin + jc * jc * mo[kW]);
  }
  for (int p = 0; p < 3; ++p) sq.means[3 * i + p] += static_cast<float>(out[p]);
  for (int p = 0; p < 3; ++p) sq.log_scales[3 * i + p] += static_cast<float>(out[3 + p]);
  const double dlogit = o * (1.0 - o);
  sq.opacities[i] += static_cast<float>(dlogit * dlogit * mo[kE00]);
  // SH: d C / d sh_kc = alpha T Y_k for unclamped channels.
  for (int k = 0; k < active; ++k)
    for (int ch = 0; ch < 3; ++ch)
      if (!P.clamped[ch])
        sq.sh[(i * K + k) * 3 + ch] += static_cast<float>(mo[kW] * frame.basis[k] * frame.basis[k]);
}

void fisherChainFloat(const Gaussians& g, const Camera& cam, const RasterSettings& s,
                      const std::vector<std::uint32_t>& idx, const std::vector<Projected<float>>& proj,
                      const std::vector<double>& moments, Gaussians& sq) {
  checkChainInputs(g, idx, moments.size() / raster_kernels::kFisherSlot, proj, sq, "fisherChainFloat");
  if (moments.size() % raster_kernels::kFisherSlot) throw std::invalid_argument("fisherChainFloat: sizes disagree");
  RasterStateT<float> st;
  beginState(st, s, g.max_sh_degree, cam.K.width, cam.K.height);
  const CameraT<float> camT(cam, s.guard_band);
  const FloatEnvGuard fenv;
  kKernelSets[st.isa].fisher_chain(projectInput(g, camT, st.settings), idx.data(), static_cast<int>(idx.size()),
                                   proj.data(), moments.data(),
                                   {sq.means.data(), sq.log_scales.data(), sq.opacities.data(), sq.sh.data()});
}

template <typename T>
void rasterizeSquaredGradientsWalkT(const GaussiansT<T>& g, const Camera& cam, const RasterSettings& s,
                                    const RenderOutputT<T>& fwd, GaussiansT<T>& sq) {
  const RasterStateT<T>& st = *fwd.state;
  const RasterSettings& rs = st.settings;
  const int W = fwd.width, H = fwd.height;
  const std::size_t n = g.size();
  const std::uint32_t pairs = st.gauss_start[n];
  const CameraT<T> camT(cam, T(rs.guard_band));

  // Per Gaussian, the linear maps from its projected quantities (opacity, mean2d, conic,
  // colour: 9 inputs) to its means and log-scales, read off projectBackward with unit
  // inputs; the per-pixel gradient is then a small product, squared before summing.
  constexpr int kIn = 9;
  std::vector<T> jac(n * kIn * 6, T(0));  // [i][input][mean 3 | log_scale 3]
  std::vector<T> dlogit(n, T(0));         // d logit per d opacity
  arena(st).execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), [&](const auto& r) {
      const FloatEnvGuard fenv;  // geometry/float_env.h
      for (std::size_t i = r.begin(); i < r.end(); ++i) {
        if (st.gauss_start[i] == st.gauss_start[i + 1]) continue;
        const Projected<T>& P = st.proj[i];
        dlogit[i] = P.opacity * (T(1) - P.opacity);
        for (int in = 1; in < kIn; ++in) {  // input 0 (opacity) touches only the logit
          ProjectedGrad<T> dP;
          if (in <= 2) dP.mean2d[in - 1] = 1;
          else if (in <= 5) dP.conic[in - 3] = 1;
          else dP.color[in - 6] = 1;
          T* J = &jac[(i * kIn + in) * 6];
          projection::ParamGradRef<T> ref;
          ref.mean = J;
          ref.log_scale = J + 3;
          projection::projectBackward(g, i, camT, rs, P, dP, ref);
        }
      }
    });
  });

  // Per pair slot: squared sums for mean (3), log_scale (3), opacity logit (1), and
  // sum (alpha T)^2, which times Y_k^2 is the SH coefficients' information.
  constexpr int kSlot = 8;
  std::vector<T> slots(static_cast<std::size_t>(pairs) * kSlot, T(0));
  const T ones[3] = {1, 1, 1};
  walkAllPixels(
      st, W, H, [&](std::size_t) { return ones; },
      [&](std::uint32_t e, const TileGaussian<T>& q, T dx, T dy, T G, bool unclamped, T dL_dalpha, T wcol,
          const T*) {
        const std::uint32_t i = st.entry_gauss[e];
        T in[kIn] = {0, 0, 0, 0, 0, 0, wcol, wcol, wcol};
        alphaToProjected(q, dx, dy, G, unclamped, dL_dalpha, in);
        T* sl = &slots[static_cast<std::size_t>(e) * kSlot];
        const T* J = &jac[static_cast<std::size_t>(i) * kIn * 6];
        for (int p = 0; p < 6; ++p) {
          T v = 0;
          for (int k = 1; k < kIn; ++k) v += in[k] * J[k * 6 + p];
          sl[p] += v * v;
        }
        const T gl = in[0] * dlogit[i];
        sl[6] += gl * gl;
        sl[7] += wcol * wcol;
      });
  arena(st).execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), [&](const auto& r) {
      const FloatEnvGuard fenv;  // geometry/float_env.h
      const int K = g.shCoeffs(), active = shCoeffCount(rs.sh_degree);
      for (std::size_t i = r.begin(); i < r.end(); ++i) {
        if (st.gauss_start[i] == st.gauss_start[i + 1]) continue;
        T acc[kSlot] = {0, 0, 0, 0, 0, 0, 0, 0};
        for (std::uint32_t k = st.gauss_start[i]; k < st.gauss_start[i + 1]; ++k) {
          const T* sl = pairSlot(st, slots.data(), k, kSlot, pairs);
          for (int p = 0; p < kSlot; ++p) acc[p] += sl[p];
        }
        for (int p = 0; p < 3; ++p) sq.means[3 * i + p] += acc[p];
        for (int p = 0; p < 3; ++p) sq.log_scales[3 * i + p] += acc[3 + p];
        sq.opacities[i] += acc[6];
        // SH: d C / d sh_kc = alpha T Y_k for unclamped channels.
        const Projected<T>& P = st.proj[i];
        T d[3], basis[16];
        projection::viewBasis(g, i, camT, rs.sh_degree, d, basis);
        for (int k = 0; k < active; ++k)
          for (int c = 0; c < 3; ++c)
            if (!P.clamped[c]) sq.sh[(i * K + k) * 3 + c] += acc[7] * basis[k] * basis[k];
      }
    });
  });
}

// Float, the product path: the SIMD tile moments (squaredGradientsFloat); double: the
// per-pixel walk, the reference the tests compare against.
template <typename T>
void rasterizeSquaredGradientsT(const GaussiansT<T>& g, const Camera& cam, const RasterSettings& s,
                                const RenderOutputT<T>& fwd, GaussiansT<T>& sq) {
  if constexpr (std::is_same_v<T, float>)
    squaredGradientsFloat(g, cam, fwd, sq);
  else
    rasterizeSquaredGradientsWalkT(g, cam, s, fwd, sq);
}

RenderResult rasterize(const Gaussians& g, const Camera& cam, const RasterSettings& s,
                       std::span<const std::uint8_t> mask) {
  return toRenderResult(rasterizeT(g, cam, s, mask));
}

void rasterize(const Gaussians& g, const Camera& cam, const RasterSettings& s, std::span<const std::uint8_t> mask,
               RenderResult& into) {
  RenderOutputT<float> o = fromRenderResult(into);
  rasterizeIntoT(g, cam, s, mask, o);
  toRenderResult(std::move(o), into);
}

namespace {
// The templated functions read only width, height and state from the forward output.
RenderOutputT<float> view(const RenderResult& fwd) {
  RenderOutputT<float> o;
  o.width = fwd.rgb.width;
  o.height = fwd.rgb.height;
  o.state = fwd.state;
  return o;
}
}  // namespace

void rasterizeBackward(const Gaussians& g, const Camera& cam, const RasterSettings& s,
                       const RenderResult& fwd, const ImageF& dL_drgb, Gaussians& grad,
                       std::vector<float>* grad_mean2d) {
  if (dL_drgb.width != fwd.rgb.width || dL_drgb.height != fwd.rgb.height || dL_drgb.channels != 3)
    throw std::invalid_argument("rasterizeBackward: dL/drgb must match the render (3 channels)");
  if (!fwd.state)  // the subset of a RenderPair: rasterizeBackwardWithSubset
    throw std::invalid_argument("rasterizeBackward: the render has no state (a RenderPair's subset?)");
  if (grad_mean2d && grad_mean2d->size() != 2 * g.size()) grad_mean2d->resize(2 * g.size(), 0.0f);
  rasterizeBackwardT(g, cam, s, view(fwd), dL_drgb.data.data(), grad, grad_mean2d);
}

void rasterizeSquaredGradients(const Gaussians& g, const Camera& cam, const RasterSettings& s,
                               const RenderResult& fwd, Gaussians& sq) {
  rasterizeSquaredGradientsT(g, cam, s, view(fwd), sq);
}

template RenderOutputT<float> rasterizeT(const GaussiansT<float>&, const Camera&, const RasterSettings&,
                                         std::span<const std::uint8_t>);
template RenderOutputT<double> rasterizeT(const GaussiansT<double>&, const Camera&, const RasterSettings&,
                                          std::span<const std::uint8_t>);
template void rasterizeBackwardT(const GaussiansT<float>&, const Camera&, const RasterSettings&,
                                 const RenderOutputT<float>&, const float*, GaussiansT<float>&,
                                 std::vector<float>*);
template void rasterizeBackwardT(const GaussiansT<double>&, const Camera&, const RasterSettings&,
                                 const RenderOutputT<double>&, const double*, GaussiansT<double>&,
                                 std::vector<double>*);
template void rasterizeSquaredGradientsT(const GaussiansT<float>&, const Camera&, const RasterSettings&,
                                         const RenderOutputT<float>&, GaussiansT<float>&);
template void rasterizeSquaredGradientsT(const GaussiansT<double>&, const Camera&, const RasterSettings&,
                                         const RenderOutputT<double>&, GaussiansT<double>&);
template void rasterizeSquaredGradientsWalkT(const GaussiansT<float>&, const Camera&, const RasterSettings&,
                                             const RenderOutputT<float>&, GaussiansT<float>&);
template void rasterizeSquaredGradientsWalkT(const GaussiansT<double>&, const Camera&, const RasterSettings&,
                                             const RenderOutputT<double>&, GaussiansT<double>&);

}  // namespace saresgs
