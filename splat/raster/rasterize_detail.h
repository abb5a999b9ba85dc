#pragma once
// The rasterizer templated on the scalar: float is the product, double serves the
// gradient tests (same code, so a double finite-difference check tests the float path's
// logic, and float-vs-double tests its rounding).
#include <memory>
#include <span>
#include <vector>

#include "splat/raster/projected.h"
#include "splat/rasterize.h"

namespace saresgs {

template <typename T>
struct RasterStateT;

template <typename T>
struct RenderOutputT {
  int width = 0, height = 0;
  std::vector<T> rgb, alpha, depth;  // 3, 1, 1 per pixel
  std::vector<int> contributors;
  std::vector<T> radii;
  std::vector<std::uint8_t> visible;
  std::shared_ptr<const RasterStateT<T>> state;
};

template <typename T>
RenderOutputT<T> rasterizeT(const GaussiansT<T>& g, const Camera& cam, const RasterSettings& s,
                            std::span<const std::uint8_t> mask = {});

// Adds dL/dparams to `grad` for dL/drgb (3 per pixel); grad_mean2d (2 per Gaussian,
// pixels) is added to when given.
template <typename T>
void rasterizeBackwardT(const GaussiansT<T>& g, const Camera& cam, const RasterSettings& s, const RenderOutputT<T>& fwd,
                        const T* dL_drgb, GaussiansT<T>& grad, std::vector<T>* grad_mean2d = nullptr);

// Adds, per parameter, sum over pixels of (d(C_r + C_g + C_b)/dparam)^2 to `sq`
// (FisherRF's diagonal information; rotations are left untouched).
template <typename T>
void rasterizeSquaredGradientsT(const GaussiansT<T>& g, const Camera& cam, const RasterSettings& s,
                                const RenderOutputT<T>& fwd, GaussiansT<T>& sq);

// The same, pixel by pixel with the Jacobian applied at every contribution: what double
// runs, and the reference for the float path's tile moments (tests only).
template <typename T>
void rasterizeSquaredGradientsWalkT(const GaussiansT<T>& g, const Camera& cam, const RasterSettings& s,
                                    const RenderOutputT<T>& fwd, GaussiansT<T>& sq);

// Rules 1-5 for Gaussians [begin, end) of a float model as every float render with `s`
// runs them (the SIMD projection of s.execution.kernels with the opacity-aware extent,
// project<float> otherwise), into out[begin, end) (out is resized to g.size()): tests hold
// the SIMD kernels to project<float> bit for bit.
void projectRangeFloat(const GaussiansT<float>& g, const Camera& cam, const RasterSettings& s, std::size_t begin,
                       std::size_t end, std::vector<projection::Projected<float>>& out);

// projectBackward<float> for Gaussians idx (distinct, each with proj[idx[j]] and dP[j])
// as every float backward pass with `s` runs it (the SIMD kernel of s.execution.kernels),
// adding to `grad`: tests hold it to the scalar projectBackward bit for bit.
void projectBackwardFloat(const GaussiansT<float>& g, const Camera& cam, const RasterSettings& s,
                          const std::vector<std::uint32_t>& idx, const std::vector<projection::Projected<float>>& proj,
                          const std::vector<projection::ProjectedGrad<float>>& dP, GaussiansT<float>& grad);

// The Fisher pass's per-Gaussian stage for Gaussian i, scalar (the reference), and for
// Gaussians idx by the SIMD kernel of s.execution.kernels (what every float Fisher pass
// runs): from its projection and its kFisherSlot tile moments summed in double
// (moments[j * kFisherSlot ...] for idx[j]), the squared gradients added to `sq`.
void fisherChainReference(const GaussiansT<float>& g, const Camera& cam, const RasterSettings& s, std::size_t i,
                          const projection::Projected<float>& P, const double* moments, GaussiansT<float>& sq);
void fisherChainFloat(const GaussiansT<float>& g, const Camera& cam, const RasterSettings& s,
                      const std::vector<std::uint32_t>& idx, const std::vector<projection::Projected<float>>& proj,
                      const std::vector<double>& moments, GaussiansT<float>& sq);

}  // namespace saresgs
