#pragma once
// The rasterizer's stages and what they share (internal to splat/raster). The passes are
// split by stage, as gsplat names them: projection (project_stage.cpp), tile binning and
// depth order (bin_stage.cpp), the forward composite (forward.cpp), the backward
// (backward.cpp), the pair of a full and a subset render for residual supervision
// (pair.cpp) and FisherRF's squared gradients (fisher_pass.cpp). Every tile pass walks the
// tiles through forEachTile. Every gradient contribution lands in a slot owned by one
// (tile, Gaussian) pair and slots are reduced per Gaussian in a fixed order, so results
// are bit-identical for the same inputs, whatever the thread count.
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "geometry/float_env.h"
#include "splat/kept_buffers.h"
#include "splat/raster/execution.h"
#include "splat/raster/projection.h"
#include "splat/raster/raster_kernels.h"
#include "splat/raster/rasterize_detail.h"

namespace saresgs {

// What a render keeps for its backward and Fisher passes (RenderOutputT::state).
template <typename T>
struct RasterStateT {
  RasterSettings settings;
  std::vector<projection::Projected<T>> proj;  // per Gaussian
  std::vector<TileGaussian<T>> tile_data;      // per Gaussian: what the tile kernels read
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
  std::vector<T> final_T;                              // per pixel
  std::vector<std::uint32_t> n_walked;                 // per pixel: tile entries walked (last contributor + 1)
  const raster_kernels::KernelSet* kernels = nullptr;  // the float kernels the forward pass used
};

namespace raster_stage {

using projection::CameraT;
using projection::Projected;
using projection::ProjectedGrad;

// The arena a pass runs in: the forward pass's execution settings (its thread count
// does not change results, so the backward pass simply reuses it).
template <typename T>
tbb::task_arena& arena(const RasterStateT<T>& st) {
  return raster_execution::arena(st.settings.execution.threads);
}

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
T rowQuad(const TileGaussian<T>& q, T dy) {
  return T(-0.5) * q.c * dy * dy;
}
template <typename T>
T rowCross(const TileGaussian<T>& q, T dy) {
  return q.b * dy;
}
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
template <typename T>
void tilePixels(const RasterStateT<T>& st, int tile, int width, int height, int& x0, int& y0, int& x1, int& y1) {
  const int tx = tile % st.tiles_x, ty = tile / st.tiles_x;
  x0 = tx * kTileSize;
  y0 = ty * kTileSize;
  x1 = std::min(width, x0 + kTileSize);
  y1 = std::min(height, y0 + kTileSize);
}

// The tile walk every tile pass shares: tiles in parallel in the render's arena, each task
// with the float environment guarded (geometry/float_env.h), the tile's Gaussians gathered
// in depth order into a list kept per thread, and its pixel rectangle [x0, x1) x [y0, y1):
// f(tile, q, x0, y0, x1, y1). A pass that has nothing to do for an empty tile returns.
template <typename T, typename F>
void forEachTile(const RasterStateT<T>& st, int W, int H, F&& f) {
  arena(st).execute([&] {
    tbb::parallel_for(0, st.tiles_x * st.tiles_y, [&](int tile) {
      const FloatEnvGuard fenv;
      thread_local std::vector<TileGaussian<T>> q;
      gatherTile(st, tile, q);
      int x0, y0, x1, y1;
      tilePixels(st, tile, W, H, x0, y0, x1, y1);
      f(tile, q, x0, y0, x1, y1);
    });
  });
}

// --- Projection (project_stage.cpp) and binning (bin_stage.cpp) --------------------------
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
std::uint32_t coverTiles(const TileGaussian<T>& g, const std::array<int, 4>& rect, int W, int H, std::uint64_t& met) {
  const int rw = metMaskWidth(rect);
  if (rw == 0) {
    std::uint32_t count = 0;
    forEachTileMet(g, rect, W, H, [&](int, int) { ++count; });
    return count;
  }
  std::uint64_t m = 0;
  forEachTileMet(g, rect, W, H,
                 [&](int tx, int ty) { m |= std::uint64_t{1} << ((ty - rect[2]) * rw + (tx - rect[0])); });
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
  st.kernels = &raster_execution::kernelSet(s.execution.kernels);
  st.settings.sh_degree = std::clamp(s.sh_degree, 0, max_sh_degree);
  st.tiles_x = (W + kTileSize - 1) / kTileSize;
  st.tiles_y = (H + kTileSize - 1) / kTileSize;
}

// The projection kernels' view of a float model and camera (raster_kernels::ProjectIn).
raster_kernels::ProjectIn projectInput(const GaussiansT<float>& g, const CameraT<float>& cam, const RasterSettings& rs);

// One Gaussian range of projectAll's projection (without its tile work).
void projectRangeWith(const GaussiansT<float>& g, const CameraT<float>& camT, const RasterSettings& rs,
                      const raster_kernels::KernelSet& kernels, std::size_t begin, std::size_t end,
                      Projected<float>* out);

// Projects every unmasked Gaussian, culls, fills its tile data, radius and visibility,
// and counts the tiles its pixel rectangle touches. `cover` is the caller's (kept between
// renders: rasterizeIntoT).
template <typename T>
void projectAll(const GaussiansT<T>& g, const CameraT<T>& camT, std::span<const std::uint8_t> mask, int W, int H,
                RasterStateT<T>& st, RenderOutputT<T>& out, TileCover& cover);

// The tests' entries to the per-Gaussian kernels: one gradient entry per listed Gaussian,
// arrays of the model's sizes, indices inside it.
void checkChainInputs(const Gaussians& g, const std::vector<std::uint32_t>& idx, std::size_t per_listed,
                      const std::vector<Projected<float>>& proj, const Gaussians& out, const char* who);

// Builds the per-tile lists: pair slots, Gaussian-major, then a stable counting sort by
// tile of the Gaussians in depth order, so each tile comes out sorted by rule 6.
template <typename T>
void binAndSort(const TileCover& cover, int W, int H, RasterStateT<T>& st);

// --- The forward composite (forward.cpp) -------------------------------------------------

// A float render's images, sized, not cleared (the float kernels write every value).
void allocateImages(int W, int H, bool depth_and_contributors, RenderOutputT<float>& out);

// The kernels' view of a render's images (depth and contributors null when left out).
raster_kernels::ForwardOut forwardOut(int W, RenderOutputT<float>& out, float* final_T, std::uint32_t* n_walked);

// The public result of a float render, moved into `r` (no copy, no allocation), and its
// buffers handed back to the templated passes (moved, so they keep their capacity).
void toRenderResult(RenderOutputT<float>&& o, RenderResult& r);
RenderResult toRenderResult(RenderOutputT<float>&& o);
RenderOutputT<float> fromRenderResult(RenderResult& r);

// The templated passes read only width, height and state from the forward output.
inline RenderOutputT<float> renderView(const RenderResult& fwd) {
  RenderOutputT<float> o;
  o.width = fwd.rgb.width;
  o.height = fwd.rgb.height;
  o.state = fwd.state;
  return o;
}

// --- What the backward (backward.cpp), the pair (pair.cpp) and Fisher share ----------------

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

inline float* keptGradSlots(KeptBuffers<GradSlots>& kept, std::uint32_t pairs) {
  std::vector<float>& v = kept.get().v;
  reserveKept(v, static_cast<std::size_t>(pairs) * kGradSlot);
  v.resize(static_cast<std::size_t>(pairs) * kGradSlot);
  return v.data();
}

// Pair k's slot of `count` values in a tile-ordered slot buffer, with the slot of pair
// k + 32 fetched ahead (both of its ends): the per-Gaussian reductions read the slots in
// pair order, which scatters over the buffer. `pairs` bounds the lookahead.
template <typename T>
inline const T* pairSlot(const RasterStateT<T>& st, const T* slots, std::uint32_t k, int count, std::uint32_t pairs) {
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
                GaussiansT<T>& grad, std::vector<T>* grad_mean2d);

// Walks one pixel's contributors back to front and calls
// visit(entry, dx, dy, G, alpha, unclamped, dL_dalpha, dL_dcolor_weight) where dL_dalpha
// is for the per-pixel objective sum_c w_c C_c and dL_dcolor_weight = alpha T.
template <typename T, typename Visit>
void walkBack(const std::vector<TileGaussian<T>>& q, std::uint32_t walked, T final_T, T px, T py, const T w[3],
              const T bg[3], Visit&& visit) {
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
  g2d[0] += G * dL_dalpha;               // opacity
  const T dG = q.o * dL_dalpha * G;      // dL/dpower
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
  forEachTile(st, W, H, [&](int tile, const std::vector<TileGaussian<T>>& q, int x0, int y0, int x1, int y1) {
    const std::uint32_t base = st.tile_start[tile];
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
}

}  // namespace raster_stage
}  // namespace saresgs
