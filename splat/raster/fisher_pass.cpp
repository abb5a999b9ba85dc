// FisherRF's squared gradients (rasterizeSquaredGradients): the float pass's SIMD tile
// moments and per-Gaussian chain, and the double per-pixel walk they are tested against.
#include "splat/raster/raster_stages.h"
#include <mutex>
#include <type_traits>

namespace saresgs::raster_stage {
namespace {

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
  const raster_kernels::FisherFn kernel = st.kernels->fisher;
  forEachTile(st, W, H, [&](int tile, const std::vector<TileGaussian<float>>& q, int x0, int y0, int x1, int y1) {
    if (q.empty()) return;
    kernel(q.data(), static_cast<int>(q.size()), x0, y0, x1, y1, bg, in,
           slots + static_cast<std::size_t>(st.tile_start[tile]) * raster_kernels::kFisherSlot);
  });
}

// Per parameter p, the per-pixel gradient is o e u_p(dx, dy) + wc Jc_p with
//   u_p = (a dx + b dy) J_mx + (b dx + c dy) J_my - dx^2 J_ca / 2 - dx dy J_cb - dy^2 J_cc / 2
// (alphaToProjected's 2D gradients through the Jacobian), so its square summed over the
// pixels is a quadratic form in the moments: o^2 k^T E k + 2 o Jc k.F + Jc^2 W, with k
// the coefficients of (dx, dy, dx^2, dx dy, dy^2) in u_p.
void squaredGradientsFloat(const Gaussians& g, const Camera& cam, const RenderOutputT<float>& fwd, Gaussians& sq) {
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
            st.kernels->fisher_chain(pin, list, listed, st.proj.data(), mo, out);
          });
    });
  });
}

}  // namespace
}  // namespace saresgs::raster_stage

namespace saresgs {
using namespace raster_stage;

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
      if (!P.clamped[ch]) sq.sh[(i * K + k) * 3 + ch] += static_cast<float>(mo[kW] * frame.basis[k] * frame.basis[k]);
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
  st.kernels->fisher_chain(projectInput(g, camT, st.settings), idx.data(), static_cast<int>(idx.size()), proj.data(),
                           moments.data(), {sq.means.data(), sq.log_scales.data(), sq.opacities.data(), sq.sh.data()});
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
          if (in <= 2)
            dP.mean2d[in - 1] = 1;
          else if (in <= 5)
            dP.conic[in - 3] = 1;
          else
            dP.color[in - 6] = 1;
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
      [&](std::uint32_t e, const TileGaussian<T>& q, T dx, T dy, T G, bool unclamped, T dL_dalpha, T wcol, const T*) {
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

void rasterizeSquaredGradients(const Gaussians& g, const Camera& cam, const RasterSettings& s, const RenderResult& fwd,
                               Gaussians& sq) {
  rasterizeSquaredGradientsT(g, cam, s, renderView(fwd), sq);
}

template void rasterizeSquaredGradientsT(const GaussiansT<float>&, const Camera&, const RasterSettings&,
                                         const RenderOutputT<float>&, GaussiansT<float>&);
template void rasterizeSquaredGradientsT(const GaussiansT<double>&, const Camera&, const RasterSettings&,
                                         const RenderOutputT<double>&, GaussiansT<double>&);
template void rasterizeSquaredGradientsWalkT(const GaussiansT<float>&, const Camera&, const RasterSettings&,
                                             const RenderOutputT<float>&, GaussiansT<float>&);
template void rasterizeSquaredGradientsWalkT(const GaussiansT<double>&, const Camera&, const RasterSettings&,
                                             const RenderOutputT<double>&, GaussiansT<double>&);

}  // namespace saresgs
