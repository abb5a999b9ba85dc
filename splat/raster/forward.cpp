// The forward composite (rule 7 of splat/rasterize.h, per pixel, front to back) and the
// forward pass's entry points: rasterizeT, rasterize.
#include "splat/raster/raster_stages.h"
#include <type_traits>
#include <utility>

namespace saresgs::raster_stage {
namespace {

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
void compositeTile(const std::vector<TileGaussian<T>>& q, int x0, int y0, int x1, int y1, const T bg[3], int W,
                   RenderOutputT<T>& out, RasterStateT<T>& st) {
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
        const bool ok =
            (ac[c] != 0) & (std::abs(dx) <= g.hx) & (power <= T(0)) & (alpha >= projection::Thresholds<T>::min_alpha);
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

raster_kernels::ForwardOut forwardOut(int W, RenderOutputT<float>& out, float* final_T, std::uint32_t* n_walked) {
  const bool aux = !out.depth.empty();
  return {W,
          out.rgb.data(),
          out.alpha.data(),
          aux ? out.depth.data() : nullptr,
          aux ? out.contributors.data() : nullptr,
          final_T,
          n_walked};
}

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

namespace {

// Composites every tile front to back (float: the SIMD kernels of st.kernels) into `out`,
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
  forEachTile(st, W, H, [&](int, const std::vector<TileGaussian<T>>& q, int x0, int y0, int x1, int y1) {
    if constexpr (std::is_same_v<T, float>) {
      const raster_kernels::ForwardOut fo = forwardOut(W, out, st.final_T.data(), st.n_walked.data());
      st.kernels->composite(q.data(), static_cast<int>(q.size()), x0, y0, x1, y1, bg, fo);
    } else {
      compositeTile(q, x0, y0, x1, y1, bg, W, out, st);
    }
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
}  // namespace saresgs::raster_stage

namespace saresgs {
using namespace raster_stage;

const char* rasterKernelName(const RasterExecution& e) { return raster_execution::kernelSet(e.kernels).name; }

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

template <typename T>
RenderOutputT<T> rasterizeT(const GaussiansT<T>& g, const Camera& cam, const RasterSettings& s,
                            std::span<const std::uint8_t> mask) {
  RenderOutputT<T> out;
  rasterizeIntoT(g, cam, s, mask, out);
  return out;
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

template RenderOutputT<float> rasterizeT(const GaussiansT<float>&, const Camera&, const RasterSettings&,
                                         std::span<const std::uint8_t>);
template RenderOutputT<double> rasterizeT(const GaussiansT<double>&, const Camera&, const RasterSettings&,
                                          std::span<const std::uint8_t>);

}  // namespace saresgs
