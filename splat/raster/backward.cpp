// The exact backward pass (dL/dparams from dL/drgb): per (tile, Gaussian) pair slots
// filled by the tile kernels, reduced per Gaussian and chained to its parameters.
#include "splat/raster/raster_stages.h"
#include <stdexcept>
#include <type_traits>

namespace saresgs::raster_stage {

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
      pout = {grad.means.data(), grad.log_scales.data(), grad.rotations.data(), grad.opacities.data(), grad.sh.data()};
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
              st.kernels->project_backward(pin, list, listed, st.proj.data(), list_dP, pout);
          });
    });
  });
}

template void chainSlots(const GaussiansT<float>&, const Camera&, const RasterStateT<float>&, const float*,
                         GaussiansT<float>&, std::vector<float>*);
template void chainSlots(const GaussiansT<double>&, const Camera&, const RasterStateT<double>&, const double*,
                         GaussiansT<double>&, std::vector<double>*);

namespace {

// Fills the backward pass's per-pair slots (9 per pair: opacity, mean2d 2, conic 3,
// colour 3). The generic version walks pixel by pixel (the double tests run it); the
// float version below is the SIMD kernel with the same arithmetic per contribution.
template <typename T>
void backwardSlots(const RasterStateT<T>& st, int W, int H, const T* dL_drgb, T* slots) {
  constexpr int kSlot = kGradSlot;
  walkAllPixels(
      st, W, H, [&](std::size_t pix) { return &dL_drgb[pix * 3]; },
      [&](std::uint32_t e, const TileGaussian<T>& q, T dx, T dy, T G, bool unclamped, T dL_dalpha, T wcol, const T* w) {
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
  const raster_kernels::BackwardFn kernel = st.kernels->backward;
  forEachTile(st, W, H, [&](int tile, const std::vector<TileGaussian<float>>& q, int x0, int y0, int x1, int y1) {
    if (q.empty()) return;
    kernel(q.data(), static_cast<int>(q.size()), x0, y0, x1, y1, bg, in,
           slots + static_cast<std::size_t>(st.tile_start[tile]) * kGradSlot);
  });
}

}  // namespace
}  // namespace saresgs::raster_stage

namespace saresgs {
using namespace raster_stage;

template <typename T>
void rasterizeBackwardT(const GaussiansT<T>& g, const Camera& cam, const RasterSettings& s, const RenderOutputT<T>& fwd,
                        const T* dL_drgb, GaussiansT<T>& grad, std::vector<T>* grad_mean2d) {
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

void rasterizeBackward(const Gaussians& g, const Camera& cam, const RasterSettings& s, const RenderResult& fwd,
                       const ImageF& dL_drgb, Gaussians& grad, std::vector<float>* grad_mean2d) {
  if (dL_drgb.width != fwd.rgb.width || dL_drgb.height != fwd.rgb.height || dL_drgb.channels != 3)
    throw std::invalid_argument("rasterizeBackward: dL/drgb must match the render (3 channels)");
  if (!fwd.state)  // the subset of a RenderPair: rasterizeBackwardWithSubset
    throw std::invalid_argument("rasterizeBackward: the render has no state (a RenderPair's subset?)");
  if (grad_mean2d && grad_mean2d->size() != 2 * g.size()) grad_mean2d->resize(2 * g.size(), 0.0f);
  rasterizeBackwardT(g, cam, s, renderView(fwd), dL_drgb.data.data(), grad, grad_mean2d);
}

template void rasterizeBackwardT(const GaussiansT<float>&, const Camera&, const RasterSettings&,
                                 const RenderOutputT<float>&, const float*, GaussiansT<float>&, std::vector<float>*);
template void rasterizeBackwardT(const GaussiansT<double>&, const Camera&, const RasterSettings&,
                                 const RenderOutputT<double>&, const double*, GaussiansT<double>&,
                                 std::vector<double>*);

}  // namespace saresgs
