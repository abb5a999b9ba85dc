// Projection (rules 1-5 of splat/rasterize.h, per Gaussian): each Gaussian's 2D mean,
// conic, extent, colour and depth, its tile data, and the tiles its alpha ellipse meets.
#include "splat/raster/raster_stages.h"
#include <stdexcept>
#include <string>

namespace saresgs::raster_stage {

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

void projectRangeWith(const GaussiansT<float>& g, const CameraT<float>& camT, const RasterSettings& rs,
                      const raster_kernels::KernelSet& kernels, std::size_t begin, std::size_t end,
                      Projected<float>* out) {
  if (rs.extent == ExtentRule::kOpacityAware) {
    kernels.project(projectInput(g, camT, rs), begin, end, out);
    return;
  }
  for (std::size_t i = begin; i < end; ++i) out[i] = projection::project(g, i, camT, rs);
}

template <typename T>
void projectAll(const GaussiansT<T>& g, const CameraT<T>& camT, std::span<const std::uint8_t> mask, int W, int H,
                RasterStateT<T>& st, RenderOutputT<T>& out, TileCover& cover) {
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
      if constexpr (std::is_same_v<T, float>)
        projectRangeWith(g, camT, rs, *st.kernels, r.begin(), r.end(), st.proj.data());
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

void checkChainInputs(const Gaussians& g, const std::vector<std::uint32_t>& idx, std::size_t per_listed,
                      const std::vector<Projected<float>>& proj, const Gaussians& out, const char* who) {
  if (idx.size() != per_listed || proj.size() != g.size() || out.size() != g.size() || out.shCoeffs() != g.shCoeffs())
    throw std::invalid_argument(std::string(who) + ": sizes disagree");
  for (const std::uint32_t i : idx)
    if (i >= g.size()) throw std::invalid_argument(std::string(who) + ": index beyond the model");
}

template void projectAll(const GaussiansT<float>&, const CameraT<float>&, std::span<const std::uint8_t>, int, int,
                         RasterStateT<float>&, RenderOutputT<float>&, TileCover&);
template void projectAll(const GaussiansT<double>&, const CameraT<double>&, std::span<const std::uint8_t>, int, int,
                         RasterStateT<double>&, RenderOutputT<double>&, TileCover&);

}  // namespace saresgs::raster_stage

namespace saresgs {
using namespace raster_stage;

void projectRangeFloat(const GaussiansT<float>& g, const Camera& cam, const RasterSettings& s, std::size_t begin,
                       std::size_t end, std::vector<projection::Projected<float>>& out) {
  if (begin > end || end > g.size()) throw std::invalid_argument("projectRangeFloat: range beyond the model");
  RasterStateT<float> st;
  beginState(st, s, g.max_sh_degree, cam.K.width, cam.K.height);
  const CameraT<float> camT(cam, s.guard_band);
  out.resize(g.size());
  const FloatEnvGuard fenv;
  projectRangeWith(g, camT, st.settings, *st.kernels, begin, end, out.data());
}

void projectBackwardFloat(const GaussiansT<float>& g, const Camera& cam, const RasterSettings& s,
                          const std::vector<std::uint32_t>& idx, const std::vector<Projected<float>>& proj,
                          const std::vector<ProjectedGrad<float>>& dP, GaussiansT<float>& grad) {
  checkChainInputs(g, idx, dP.size(), proj, grad, "projectBackwardFloat");
  RasterStateT<float> st;
  beginState(st, s, g.max_sh_degree, cam.K.width, cam.K.height);
  const CameraT<float> camT(cam, s.guard_band);
  const FloatEnvGuard fenv;
  st.kernels->project_backward(
      projectInput(g, camT, st.settings), idx.data(), static_cast<int>(idx.size()), proj.data(), dP.data(),
      {grad.means.data(), grad.log_scales.data(), grad.rotations.data(), grad.opacities.data(), grad.sh.data()});
}

}  // namespace saresgs
