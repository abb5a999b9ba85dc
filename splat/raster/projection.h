#pragma once
// Per-Gaussian projection (rules 1-5 of splat/rasterize.h) and its exact backward,
// templated on the scalar so the float fast path and double gradient tests share it.
#include <algorithm>
#include <cmath>
#include <limits>

#include "geometry/camera/camera.h"
#include "splat/gaussians.h"
#include "splat/rasterize.h"
#include "splat/raster/projected.h"
#include "splat/raster/sh.h"

namespace saresgs::projection {

// The contract's thresholds (splat/rasterize.h) in the working scalar: the float values
// for the float path; for double, the decimal values the reference renderer uses
// (reference_renderer.cpp), so that the double fast path makes the reference's exact
// decisions (1/255 in float is 6e-8 relative above 1/255 in double: with the float
// value a 2048x1536 render of large Gaussians skipped a contribution the reference
// took; FastVsReference.ExtremeFieldsOfViewPrincipalPointsAndImageSizes).
template <typename T>
struct Thresholds {
  static constexpr T min_alpha = kMinAlpha, max_alpha = kMaxAlpha, min_transmittance = kMinTransmittance;
};
template <>
struct Thresholds<double> {
  static constexpr double min_alpha = 1.0 / 255.0, max_alpha = 0.99, min_transmittance = 1e-4;
};

template <typename T>
struct Mat3 {
  T m[3][3];
};

// Camera constants in the working scalar.
template <typename T>
struct CameraT {
  T R[3][3];
  T t[3];
  T center[3];
  T fx, fy, cx, cy;
  int width, height;
  // Guard band in x/z and y/z (rule 1).
  T gx_mid, gx_half, gy_mid, gy_half;

  CameraT(const Camera& c, T guard_band) {
    for (int r = 0; r < 3; ++r) {
      for (int k = 0; k < 3; ++k) R[r][k] = T(c.R(r, k));
      t[r] = T(c.t(r));
    }
    const Eigen::Vector3d C = c.center();
    for (int r = 0; r < 3; ++r) center[r] = T(C(r));
    fx = T(c.K.fx);
    fy = T(c.K.fy);
    cx = T(c.K.cx);
    cy = T(c.K.cy);
    width = c.K.width;
    height = c.K.height;
    const double l = -c.K.cx / c.K.fx, r = (c.K.width - c.K.cx) / c.K.fx;
    const double tp = -c.K.cy / c.K.fy, b = (c.K.height - c.K.cy) / c.K.fy;
    gx_mid = T(0.5 * (l + r));
    gx_half = T(0.5 * (r - l)) * guard_band;
    gy_mid = T(0.5 * (tp + b));
    gy_half = T(0.5 * (b - tp)) * guard_band;
  }
};

// Rotation matrix of a quaternion (w, x, y, z), normalised here; zero -> identity.
template <typename T>
Mat3<T> quatToRot(const T* q, T* qn_out = nullptr, T* norm_out = nullptr) {
  const T n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  T w = 1, x = 0, y = 0, z = 0;
  if (n > T(1e-12)) {
    w = q[0] / n;
    x = q[1] / n;
    y = q[2] / n;
    z = q[3] / n;
  }
  if (qn_out) {
    qn_out[0] = w;
    qn_out[1] = x;
    qn_out[2] = y;
    qn_out[3] = z;
  }
  if (norm_out) *norm_out = n;
  Mat3<T> R;
  R.m[0][0] = 1 - 2 * (y * y + z * z);
  R.m[0][1] = 2 * (x * y - w * z);
  R.m[0][2] = 2 * (x * z + w * y);
  R.m[1][0] = 2 * (x * y + w * z);
  R.m[1][1] = 1 - 2 * (x * x + z * z);
  R.m[1][2] = 2 * (y * z - w * x);
  R.m[2][0] = 2 * (x * z - w * y);
  R.m[2][1] = 2 * (y * z + w * x);
  R.m[2][2] = 1 - 2 * (x * x + y * y);
  return R;
}

// exp of a log-scale, kept finite: scales beyond e^±60 cannot be represented usefully in
// float anyway, and clamping here keeps covariances finite for any stored value.
template <typename T>
T safeExp(T v) {
  return std::exp(std::clamp(v, T(-60), T(60)));
}

template <typename T>
T sigmoid(T v) {
  return T(1) / (T(1) + std::exp(-std::clamp(v, T(-80), T(80))));
}

// Rules 1-5 for Gaussian i.
// The SH basis along the unit view direction from the camera centre to Gaussian i's
// mean (zero when they coincide), written to d and basis; returns the distance, which
// the backward pass needs to chain through the normalisation. Forward, backward and the
// Fisher pass share it, so all three see the same direction bit for bit.
template <typename T>
T viewBasis(const GaussiansT<T>& g, std::size_t i, const CameraT<T>& cam, int sh_degree, T d[3], T basis[16]) {
  const T* m = &g.means[3 * i];
  d[0] = m[0] - cam.center[0];
  d[1] = m[1] - cam.center[1];
  d[2] = m[2] - cam.center[2];
  const T dn = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  for (int k = 0; k < 3; ++k) d[k] = dn > 0 ? d[k] / dn : T(0);
  shBasis(sh_degree, d[0], d[1], d[2], basis);
  return dn;
}

template <typename T>
Projected<T> project(const GaussiansT<T>& g, std::size_t i, const CameraT<T>& cam, const RasterSettings& s) {
  Projected<T> P;
  const T* m = &g.means[3 * i];
  T p[3];
  for (int r = 0; r < 3; ++r) p[r] = cam.R[r][0] * m[0] + cam.R[r][1] * m[1] + cam.R[r][2] * m[2] + cam.t[r];
  if (!(p[2] >= T(s.near_plane))) return P;  // also rejects NaN
  const T xz = p[0] / p[2], yz = p[1] / p[2];
  if (!(std::abs(xz - cam.gx_mid) <= cam.gx_half && std::abs(yz - cam.gy_mid) <= cam.gy_half)) return P;
  const T o = sigmoid(g.opacities[i]);
  if (!(o >= Thresholds<T>::min_alpha)) return P;

  // Sigma = M M^T, M = Rq S.
  const Mat3<T> Rq = quatToRot(&g.rotations[4 * i]);
  T M[3][3];
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) M[r][k] = Rq.m[r][k] * safeExp(g.log_scales[3 * i + k]);
  T Sig[3][3];
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) Sig[r][k] = M[r][0] * M[k][0] + M[r][1] * M[k][1] + M[r][2] * M[k][2];
  // A = J W (2x3).
  const T iz = T(1) / p[2];
  const T J[2][3] = {{cam.fx * iz, 0, -cam.fx * p[0] * iz * iz}, {0, cam.fy * iz, -cam.fy * p[1] * iz * iz}};
  T A[2][3];
  for (int r = 0; r < 2; ++r)
    for (int k = 0; k < 3; ++k) A[r][k] = J[r][0] * cam.R[0][k] + J[r][1] * cam.R[1][k] + J[r][2] * cam.R[2][k];
  T AS[2][3];
  for (int r = 0; r < 2; ++r)
    for (int k = 0; k < 3; ++k) AS[r][k] = A[r][0] * Sig[0][k] + A[r][1] * Sig[1][k] + A[r][2] * Sig[2][k];
  const T ca = AS[0][0] * A[0][0] + AS[0][1] * A[0][1] + AS[0][2] * A[0][2] + T(s.eps2d);
  const T cb = AS[0][0] * A[1][0] + AS[0][1] * A[1][1] + AS[0][2] * A[1][2];
  const T cc = AS[1][0] * A[1][0] + AS[1][1] * A[1][1] + AS[1][2] * A[1][2] + T(s.eps2d);
  const T det = ca * cc - cb * cb;
  if (!(det > T(0)) || !std::isfinite(det)) return P;

  P.mean2d[0] = cam.fx * xz + cam.cx;
  P.mean2d[1] = cam.fy * yz + cam.cy;
  P.cov2d[0] = ca;
  P.cov2d[1] = cb;
  P.cov2d[2] = cc;
  P.conic[0] = cc / det;
  P.conic[1] = -cb / det;
  P.conic[2] = ca / det;
  P.depth = p[2];
  P.opacity = o;

  // Rule 4: screen rectangle.
  if (s.extent == ExtentRule::kOpacityAware) {
    const T k2 = T(2) * std::log(T(255) * o);
    P.half[0] = std::sqrt(std::max(T(0), k2 * ca));
    P.half[1] = std::sqrt(std::max(T(0), k2 * cc));
  } else {
    const T mid = T(0.5) * (ca + cc);
    const T lmax = mid + std::sqrt(std::max(T(0), mid * mid - det));
    P.half[0] = P.half[1] = T(3) * std::sqrt(lmax);
  }
  P.radius = std::max(P.half[0], P.half[1]);
  if (P.mean2d[0] + P.half[0] < 0 || P.mean2d[0] - P.half[0] > T(cam.width) || P.mean2d[1] + P.half[1] < 0 ||
      P.mean2d[1] - P.half[1] > T(cam.height) || !std::isfinite(P.radius))
    return P;

  // Rule 5: colour from SH along the view direction.
  T d[3], basis[16];
  viewBasis(g, i, cam, s.sh_degree, d, basis);
  const int K = g.shCoeffs(), active = shCoeffCount(s.sh_degree);
  const T* sh = &g.sh[static_cast<std::size_t>(i) * K * 3];
  for (int c = 0; c < 3; ++c) {
    T v = T(0.5);
    for (int k = 0; k < active; ++k) v += basis[k] * sh[k * 3 + c];
    P.clamped[c] = v < 0;
    P.color[c] = std::max(v, T(0));
  }
  P.visible = true;
  return P;
}

// Where projectBackward adds one Gaussian's parameter gradients; a null pointer skips
// that parameter (the Fisher mode asks for means and scales only).
template <typename T>
struct ParamGradRef {
  T* mean = nullptr;       // 3
  T* log_scale = nullptr;  // 3
  T* rotation = nullptr;   // 4
  T* opacity = nullptr;    // 1 (logit)
  T* sh = nullptr;         // shCoeffs * 3

  static ParamGradRef of(GaussiansT<T>& grad, std::size_t i) {
    const std::size_t K = static_cast<std::size_t>(grad.shCoeffs());
    return {&grad.means[3 * i], &grad.log_scales[3 * i], &grad.rotations[4 * i], &grad.opacities[i],
            &grad.sh[i * K * 3]};
  }
};

// What projectBackward recomputes of project() for Gaussian i, independent of the
// incoming gradients: computed once, it serves several backward calls (the Fisher pass
// reads a Jacobian off six of them).
template <typename T>
struct BackwardFrame {
  T p[3];  // camera-space mean
  T iz, iz2;
  T d[3], dn, basis[16];  // viewBasis
  Mat3<T> Rq;
  T sc[3];
  T M[3][3], Sig[3][3];
  T A[2][3];  // J W
};

template <typename T>
BackwardFrame<T> backwardFrame(const GaussiansT<T>& g, std::size_t i, const CameraT<T>& cam, const RasterSettings& s) {
  BackwardFrame<T> f;
  const T* m = &g.means[3 * i];
  for (int r = 0; r < 3; ++r) f.p[r] = cam.R[r][0] * m[0] + cam.R[r][1] * m[1] + cam.R[r][2] * m[2] + cam.t[r];
  f.iz = T(1) / f.p[2];
  f.iz2 = f.iz * f.iz;
  f.dn = viewBasis(g, i, cam, s.sh_degree, f.d, f.basis);
  f.Rq = quatToRot(&g.rotations[4 * i]);
  for (int k = 0; k < 3; ++k) f.sc[k] = safeExp(g.log_scales[3 * i + k]);
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) f.M[r][k] = f.Rq.m[r][k] * f.sc[k];
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) f.Sig[r][k] = f.M[r][0] * f.M[k][0] + f.M[r][1] * f.M[k][1] + f.M[r][2] * f.M[k][2];
  const T J[2][3] = {{cam.fx * f.iz, 0, -cam.fx * f.p[0] * f.iz2}, {0, cam.fy * f.iz, -cam.fy * f.p[1] * f.iz2}};
  for (int r = 0; r < 2; ++r)
    for (int k = 0; k < 3; ++k) f.A[r][k] = J[r][0] * cam.R[0][k] + J[r][1] * cam.R[1][k] + J[r][2] * cam.R[2][k];
  return f;
}

// The stages of projectBackward (below), apart so that the Fisher pass's Jacobian
// (projectJacobian) runs only the stages each of its inputs reaches, with the same
// arithmetic. `f` is backwardFrame(g, i, cam, s) throughout.

// Colour -> SH coefficients (added to out_sh when given) and the view direction's
// gradient, added to dm (world space, through the normalisation).
template <typename T>
void colorBackward(const GaussiansT<T>& g, std::size_t i, const RasterSettings& s, const Projected<T>& P,
                   const BackwardFrame<T>& f, const T dcolor[3], T* out_sh, T dm[3]) {
  const T* d = f.d;
  const T* basis = f.basis;
  const T dn = f.dn;
  const int K = g.shCoeffs(), active = shCoeffCount(s.sh_degree);
  const T* sh = &g.sh[i * K * 3];
  T dc[3];
  for (int c = 0; c < 3; ++c) dc[c] = P.clamped[c] ? T(0) : dcolor[c];
  if (out_sh)
    for (int k = 0; k < active; ++k)
      for (int c = 0; c < 3; ++c) out_sh[k * 3 + c] += dc[c] * basis[k];
  if (s.sh_degree > 0 && dn > 0) {
    // dL/d(basis_k) = sum_c dc_c sh_kc; then through dY_k/dd and the normalisation.
    T gb[16];
    for (int k = 0; k < active; ++k) gb[k] = dc[0] * sh[k * 3] + dc[1] * sh[k * 3 + 1] + dc[2] * sh[k * 3 + 2];
    const T x = d[0], y = d[1], z = d[2];
    T gd[3] = {0, 0, 0};
    using namespace sh_constants;
    const T c1 = T(C1);
    gd[0] += -c1 * gb[3];
    gd[1] += -c1 * gb[1];
    gd[2] += c1 * gb[2];
    if (s.sh_degree > 1) {
      const T c20 = T(C2[0]), c21 = T(C2[1]), c22 = T(C2[2]), c23 = T(C2[3]), c24 = T(C2[4]);
      gd[0] += c20 * y * gb[4] - 2 * c22 * x * gb[6] + c23 * z * gb[7] + 2 * c24 * x * gb[8];
      gd[1] += c20 * x * gb[4] + c21 * z * gb[5] - 2 * c22 * y * gb[6] - 2 * c24 * y * gb[8];
      gd[2] += c21 * y * gb[5] + 4 * c22 * z * gb[6] + c23 * x * gb[7];
    }
    if (s.sh_degree > 2) {
      const T xx = x * x, yy = y * y, zz = z * z;
      const T c30 = T(C3[0]), c31 = T(C3[1]), c32 = T(C3[2]), c33 = T(C3[3]), c34 = T(C3[4]), c35 = T(C3[5]),
              c36 = T(C3[6]);
      gd[0] += 6 * c30 * x * y * gb[9] + c31 * y * z * gb[10] - 2 * c32 * x * y * gb[11] - 6 * c33 * x * z * gb[12] +
               c34 * (4 * zz - 3 * xx - yy) * gb[13] + 2 * c35 * x * z * gb[14] + c36 * (3 * xx - 3 * yy) * gb[15];
      gd[1] += c30 * (3 * xx - 3 * yy) * gb[9] + c31 * x * z * gb[10] + c32 * (4 * zz - xx - 3 * yy) * gb[11] -
               6 * c33 * y * z * gb[12] - 2 * c34 * x * y * gb[13] - 2 * c35 * y * z * gb[14] -
               6 * c36 * x * y * gb[15];
      gd[2] += c31 * x * y * gb[10] + 8 * c32 * y * z * gb[11] + c33 * (6 * zz - 3 * xx - 3 * yy) * gb[12] +
               8 * c34 * x * z * gb[13] + c35 * (xx - yy) * gb[14];
    }
    // d = v / |v|: dL/dv = (gd - d (d . gd)) / |v|.
    const T dot = gd[0] * d[0] + gd[1] * d[1] + gd[2] * d[2];
    for (int r = 0; r < 3; ++r) dm[r] += (gd[r] - d[r] * dot) / dn;
  }
}

// Conic -> the camera-space mean's gradient gpc (J's dependence on p) and dL/dM.
template <typename T>
void conicBackward(const CameraT<T>& cam, const Projected<T>& P, const BackwardFrame<T>& f, const T dconic[3], T gpc[3],
                   T gM[3][3]) {
  const T* p = f.p;
  const T iz = f.iz, iz2 = f.iz2;
  // Covariance chain: conic -> Sigma2D -> (A, Sigma) -> (J, M) -> (p, scales, rotation).
  const T a = P.conic[0], b = P.conic[1], c = P.conic[2];
  // dL/dQ as a symmetric matrix, Q = [[a, b], [b, c]]; b appears twice in Q.
  const T gQ00 = dconic[0], gQ01 = T(0.5) * dconic[1], gQ11 = dconic[2];
  // dL/dSigma2D = -Q gQ Q.
  const T t00 = a * gQ00 + b * gQ01, t01 = a * gQ01 + b * gQ11;
  const T t10 = b * gQ00 + c * gQ01, t11 = b * gQ01 + c * gQ11;
  const T G00 = -(t00 * a + t01 * b), G01 = -(t00 * b + t01 * c), G11 = -(t10 * b + t11 * c);
  const T G2[2][2] = {{G00, G01}, {G01, G11}};

  const auto& M = f.M;
  const auto& Sig = f.Sig;
  const auto& A = f.A;

  // dL/dSigma = A^T G2 A (3x3, symmetric).
  T G2A[2][3];
  for (int r = 0; r < 2; ++r)
    for (int k = 0; k < 3; ++k) G2A[r][k] = G2[r][0] * A[0][k] + G2[r][1] * A[1][k];
  T gSig[3][3];
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) gSig[r][k] = A[0][r] * G2A[0][k] + A[1][r] * G2A[1][k];
  // dL/dA = 2 G2 A Sigma.
  T gA[2][3];
  for (int r = 0; r < 2; ++r)
    for (int k = 0; k < 3; ++k)
      gA[r][k] = T(2) * (G2A[r][0] * Sig[0][k] + G2A[r][1] * Sig[1][k] + G2A[r][2] * Sig[2][k]);
  // dL/dJ = dL/dA W^T.
  T gJ[2][3];
  for (int r = 0; r < 2; ++r)
    for (int k = 0; k < 3; ++k) gJ[r][k] = gA[r][0] * cam.R[k][0] + gA[r][1] * cam.R[k][1] + gA[r][2] * cam.R[k][2];
  // J's dependence on p.
  gpc[0] = gJ[0][2] * (-cam.fx * iz2);
  gpc[1] = gJ[1][2] * (-cam.fy * iz2);
  gpc[2] = gJ[0][0] * (-cam.fx * iz2) + gJ[0][2] * (T(2) * cam.fx * p[0] * iz2 * iz) + gJ[1][1] * (-cam.fy * iz2) +
           gJ[1][2] * (T(2) * cam.fy * p[1] * iz2 * iz);
  // Sigma = M M^T: dL/dM = 2 gSig M.
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) gM[r][k] = T(2) * (gSig[r][0] * M[0][k] + gSig[r][1] * M[1][k] + gSig[r][2] * M[2][k]);
}

// Adds the 2D mean's gradient to gpc, giving the camera-space mean's gradient gp (the
// same sums, in the same order, as one expression would).
template <typename T>
void mean2dBackward(const CameraT<T>& cam, const BackwardFrame<T>& f, const T dmean2d[2], const T gpc[3], T gp[3]) {
  const T* p = f.p;
  const T iz = f.iz, iz2 = f.iz2;
  gp[0] = gpc[0] + dmean2d[0] * cam.fx * iz;
  gp[1] = gpc[1] + dmean2d[1] * cam.fy * iz;
  gp[2] = gpc[2] - dmean2d[0] * cam.fx * p[0] * iz2 - dmean2d[1] * cam.fy * p[1] * iz2;
}

// p = W m + t: adds the mean's gradient, the view direction's dm included, to out_mean.
template <typename T>
void cameraToMean(const CameraT<T>& cam, const T gp[3], const T dm[3], T* out_mean) {
  for (int k = 0; k < 3; ++k) out_mean[k] += cam.R[0][k] * gp[0] + cam.R[1][k] * gp[1] + cam.R[2][k] * gp[2] + dm[k];
}

// M = Rq diag(sc): adds the log-scales' gradient to out_log_scale (none where the scale
// is clamped).
template <typename T>
void scaleBackward(const GaussiansT<T>& g, std::size_t i, const BackwardFrame<T>& f, const T gM[3][3],
                   T* out_log_scale) {
  const Mat3<T>& Rq = f.Rq;
  const T* sc = f.sc;
  for (int k = 0; k < 3; ++k) {
    const T gs = Rq.m[0][k] * gM[0][k] + Rq.m[1][k] * gM[1][k] + Rq.m[2][k] * gM[2][k];
    const T raw = g.log_scales[3 * i + k];
    if (raw > T(-60) && raw < T(60)) out_log_scale[k] += gs * sc[k];
  }
}

// Adds the parameter gradients of Gaussian i, given the gradients of its projected
// quantities, to `out`. Exact chain rule of project(). Flattened: the stages, called
// apart by projectJacobian, would otherwise stay out-of-line here too (3 % more
// instructions in the whole training backward pass under callgrind; 1 % with it).
template <typename T>
[[gnu::flatten]] void projectBackward(const GaussiansT<T>& g, std::size_t i, const CameraT<T>& cam,
                                      const RasterSettings& s, const Projected<T>& P, const ProjectedGrad<T>& dP,
                                      const ParamGradRef<T>& out, const BackwardFrame<T>& f) {
  // Opacity logit.
  if (out.opacity) *out.opacity += dP.opacity * P.opacity * (T(1) - P.opacity);
  T dm[3] = {0, 0, 0};
  colorBackward(g, i, s, P, f, dP.color, out.sh, dm);
  T gpc[3], gp[3], gM[3][3];
  conicBackward(cam, P, f, dP.conic, gpc, gM);
  mean2dBackward(cam, f, dP.mean2d, gpc, gp);
  if (out.mean) cameraToMean(cam, gp, dm, out.mean);
  if (out.log_scale) scaleBackward(g, i, f, gM, out.log_scale);
  const T* sc = f.sc;
  if (!out.rotation) return;
  T gR[3][3];
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) gR[r][k] = gM[r][k] * sc[k];
  T qn[4], qnorm;
  quatToRot(&g.rotations[4 * i], qn, &qnorm);
  if (qnorm > T(1e-12)) {
    const T w = qn[0], x = qn[1], y = qn[2], z = qn[3];
    T gq[4];
    gq[0] = 2 * (-z * gR[0][1] + y * gR[0][2] + z * gR[1][0] - x * gR[1][2] - y * gR[2][0] + x * gR[2][1]);
    gq[1] = 2 * (y * gR[0][1] + z * gR[0][2] + y * gR[1][0] - 2 * x * gR[1][1] - w * gR[1][2] + z * gR[2][0] +
                 w * gR[2][1] - 2 * x * gR[2][2]);
    gq[2] = 2 * (-2 * y * gR[0][0] + x * gR[0][1] + w * gR[0][2] + x * gR[1][0] + z * gR[1][2] - w * gR[2][0] +
                 z * gR[2][1] - 2 * y * gR[2][2]);
    gq[3] = 2 * (-2 * z * gR[0][0] - w * gR[0][1] + x * gR[0][2] + w * gR[1][0] - 2 * z * gR[1][1] + y * gR[1][2] +
                 x * gR[2][0] + y * gR[2][1]);
    // Through the normalisation q / |q|.
    const T dot = gq[0] * qn[0] + gq[1] * qn[1] + gq[2] * qn[2] + gq[3] * qn[3];
    for (int k = 0; k < 4; ++k) out.rotation[k] += (gq[k] - qn[k] * dot) / qnorm;
  }
}

// Gaussian i's Jacobian for the Fisher pass: row r is what projectBackward adds to the
// means (columns 0-2) and log-scales (3-5) for a unit gradient of input r: the 2D mean
// x, y (rows 0, 1), the conic a, b, c (2-4) and all three colour channels at once (5).
// Each row runs only the stages its input reaches; the conic rows use the chain's
// low-rank form (equal to projectBackward's up to rounding).
template <typename T>
void projectJacobian(const GaussiansT<T>& g, std::size_t i, const CameraT<T>& cam, const RasterSettings& s,
                     const Projected<T>& P, const BackwardFrame<T>& f, T J[6][6]) {
  for (int r = 0; r < 6; ++r)
    for (int k = 0; k < 6; ++k) J[r][k] = 0;
  const T zero3[3] = {0, 0, 0};
  for (int r = 0; r < 2; ++r) {
    const T dmean2d[2] = {T(r == 0), T(r == 1)};
    T gp[3];
    mean2dBackward(cam, f, dmean2d, zero3, gp);
    cameraToMean(cam, gp, zero3, J[r]);
  }
  // The conic rows: conicBackward for a unit gradient of conic a, b or c, in closed form.
  // dL/dSigma2D = -Q gQ Q is -(u v^T + v u^T) / 2 with u, v among Q's columns q1 = (a, b),
  // q2 = (b, c): (q1, q1) for a, (q1, q2) for b (it appears twice in Q), (q2, q2) for c.
  // Each stage of the chain then stays of that form: with r = A^T u (and A^T v),
  // dL/dSigma = -(r_u r_v^T + r_v r_u^T) / 2, dL/dA = -(u (Sig r_v)^T + v (Sig r_u)^T), and,
  // as M = Rq diag(sc), dL/dlog_scale_k = -2 sc_k^2 (Rq^T r_u)_k (Rq^T r_v)_k.
  const T q[2][2] = {{P.conic[0], P.conic[1]}, {P.conic[1], P.conic[2]}};
  T rA[2][3], wR[2][3], tR[2][3];
  for (int j = 0; j < 2; ++j) {
    for (int k = 0; k < 3; ++k) rA[j][k] = q[j][0] * f.A[0][k] + q[j][1] * f.A[1][k];
    T sS[3];
    for (int k = 0; k < 3; ++k) sS[k] = f.Sig[k][0] * rA[j][0] + f.Sig[k][1] * rA[j][1] + f.Sig[k][2] * rA[j][2];
    for (int k = 0; k < 3; ++k) wR[j][k] = cam.R[k][0] * sS[0] + cam.R[k][1] * sS[1] + cam.R[k][2] * sS[2];
    for (int k = 0; k < 3; ++k) tR[j][k] = f.Rq.m[0][k] * rA[j][0] + f.Rq.m[1][k] * rA[j][1] + f.Rq.m[2][k] * rA[j][2];
  }
  const T* p = f.p;
  const T iz = f.iz, iz2 = f.iz2;
  const int uv[3][2] = {{0, 0}, {0, 1}, {1, 1}};
  for (int r = 0; r < 3; ++r) {
    const int u = uv[r][0], v = uv[r][1];
    // dL/dJ = dL/dA W^T = -(u (W Sig r_v)^T + v (W Sig r_u)^T).
    T gJ[2][3];
    for (int row = 0; row < 2; ++row)
      for (int k = 0; k < 3; ++k) gJ[row][k] = -(q[u][row] * wR[v][k] + q[v][row] * wR[u][k]);
    T gp[3];
    gp[0] = gJ[0][2] * (-cam.fx * iz2);
    gp[1] = gJ[1][2] * (-cam.fy * iz2);
    gp[2] = gJ[0][0] * (-cam.fx * iz2) + gJ[0][2] * (T(2) * cam.fx * p[0] * iz2 * iz) + gJ[1][1] * (-cam.fy * iz2) +
            gJ[1][2] * (T(2) * cam.fy * p[1] * iz2 * iz);
    cameraToMean(cam, gp, zero3, J[2 + r]);
    for (int k = 0; k < 3; ++k) {
      const T raw = g.log_scales[3 * i + k];
      if (raw > T(-60) && raw < T(60)) J[2 + r][3 + k] = T(-2) * f.sc[k] * f.sc[k] * tR[u][k] * tR[v][k];
    }
  }
  const T ones[3] = {1, 1, 1};
  T dm[3] = {0, 0, 0};
  colorBackward(g, i, s, P, f, ones, static_cast<T*>(nullptr), dm);
  cameraToMean(cam, zero3, dm, J[5]);
}

template <typename T>
void projectBackward(const GaussiansT<T>& g, std::size_t i, const CameraT<T>& cam, const RasterSettings& s,
                     const Projected<T>& P, const ProjectedGrad<T>& dP, const ParamGradRef<T>& out) {
  projectBackward(g, i, cam, s, P, dP, out, backwardFrame(g, i, cam, s));
}

}  // namespace saresgs::projection
