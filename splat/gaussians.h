#pragma once
// The Gaussian model in structure-of-arrays form. The same type holds parameters,
// their gradients and optimiser moments, so every per-parameter loop is one loop.
//
// Storage (as 3DGS stores them, so a .ply round trip is exact):
//   means       3 floats per Gaussian (world x, y, z)
//   log_scales  3 floats (the scale is exp(log_scale) along the local axes)
//   rotations   4 floats, quaternion (w, x, y, z), normalised on use; a zero
//               quaternion is read as the identity
//   opacities   1 float, the logit (opacity = sigmoid(logit))
//   sh          sh_coeffs * 3 floats, coefficient-major: sh[(i*K + k)*3 + c] is
//               coefficient k of colour channel c of Gaussian i; k = 0 is DC
// K = sh_coeffs = (max_sh_degree + 1)^2. The active degree is a render setting, so a
// model may hold degree-3 coefficients and render at degree 0.
#include <cstddef>
#include <vector>

#include "splat/raster/constants.h"  // kShC0

namespace saresgs {

inline constexpr int shCoeffCount(int degree) { return (degree + 1) * (degree + 1); }

// Templated on the scalar so that gradient tests can run the same code in double.
template <typename T>
struct GaussiansT {
  using Scalar = T;
  int max_sh_degree = 0;
  std::vector<T> means;
  std::vector<T> log_scales;
  std::vector<T> rotations;
  std::vector<T> opacities;
  std::vector<T> sh;

  int shCoeffs() const { return shCoeffCount(max_sh_degree); }
  std::size_t size() const { return opacities.size(); }
  // Resizes every array for n Gaussians (new entries zero).
  void resize(std::size_t n) {
    forEachArray([n](std::vector<T>& a, std::size_t per) { a.resize(n * per, T(0)); });
  }
  // A zero-filled model of the same shape (for gradients and moments).
  GaussiansT zerosLike() const {
    GaussiansT z;
    z.max_sh_degree = max_sh_degree;
    z.resize(size());
    return z;
  }
  // The same model in another scalar type.
  template <typename U>
  GaussiansT<U> cast() const {
    GaussiansT<U> out;
    out.max_sh_degree = max_sh_degree;
    out.means.assign(means.begin(), means.end());
    out.log_scales.assign(log_scales.begin(), log_scales.end());
    out.rotations.assign(rotations.begin(), rotations.end());
    out.opacities.assign(opacities.begin(), opacities.end());
    out.sh.assign(sh.begin(), sh.end());
    return out;
  }
  // Calls f(array, floats per Gaussian) for each of the five arrays, in a fixed order.
  template <typename F>
  void forEachArray(F&& f) {
    f(means, 3);
    f(log_scales, 3);
    f(rotations, 4);
    f(opacities, 1);
    f(sh, static_cast<std::size_t>(shCoeffs()) * 3);
  }
  template <typename F>
  void forEachArray(F&& f) const {
    f(means, 3);
    f(log_scales, 3);
    f(rotations, 4);
    f(opacities, 1);
    f(sh, static_cast<std::size_t>(shCoeffs()) * 3);
  }
};

using Gaussians = GaussiansT<float>;
using GaussiansD = GaussiansT<double>;

}  // namespace saresgs
