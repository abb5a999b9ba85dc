// The projection kernels (rules 1-5, splat/raster/raster_kernels.h's projectRange):
// projection::project<float> with the opacity-aware extent, KernelIsa::kLanes Gaussians
// at a time, on splat/raster/raster_kernels_impl.h's vector types.
//
// Bit for bit project<float>: every lane runs project()'s operations in its order, each
// correctly rounded (no FMA contraction here or there; sqrt and division are IEEE in both),
// the zero entries of J included (0 x R is +-0 and its sign reaches A), and the
// exponentials and the logarithm are libm's expf and logf, called lane by lane, as the
// scalar code calls them. Where project() returns early (a cull) a lane carries on with
// the values it has and ends with visible = false. Tests: ProjectKernels.*
// (tests/splat/raster/test_project_kernels.cpp).
#pragma once
#include "splat/raster/raster_kernels_impl.h"
#include "splat/raster/sh_constants.h"

namespace saresgs::raster_kernels {
namespace {

// libm's expf and logf lane by lane (the scalar path's own calls).
inline vf lanesExp(vf x) {
  for (int l = 0; l < L; ++l) x[l] = __builtin_expf(x[l]);
  return x;
}
inline vf lanesLog(vf x) {
  for (int l = 0; l < L; ++l) x[l] = __builtin_logf(x[l]);
  return x;
}
// std::clamp(v, lo, hi): v < lo ? lo : (hi < v ? hi : v), NaN kept.
inline vf clampLanes(vf v, float lo, float hi) {
  const vf vlo = vs(lo), vhi = vs(hi);
  return v < vlo ? vlo : (vhi < v ? vhi : v);
}
inline vf absLanes(vf v) { return reinterpret_cast<vf>(reinterpret_cast<vi>(v) & 0x7fffffff); }
inline vi finiteLanes(vf v) { return absLanes(v) <= vs(3.40282347e+38f); }
// std::max(T(0), v): 0 < v ? v : 0 (NaN gives 0).
inline vf maxZeroLanes(vf v) { return vs(0.0f) < v ? v : vs(0.0f); }

constexpr float kProjShC0 = static_cast<float>(kShC0);  // splat/raster/constants.h

// The L Gaussians of a vector: their indices (a short last vector repeats its last
// Gaussian; only the first n lanes are written back) and per-lane loads of their arrays.
struct LaneSet {
  std::size_t ix[L];
  int n;
  vf at(const float* a, std::size_t per, std::size_t off) const {
    vf v;
    for (int l = 0; l < L; ++l) v[l] = a[ix[l] * per + off];
    return v;
  }
};

// Lanes j0 .. j0 + L - 1 of a list idx[0, count) (a short last vector repeats its last
// entry): the Gaussians in ls, their list positions in jx.
inline LaneSet listLanes(const std::uint32_t* idx, int count, int j0, int jx[L]) {
  LaneSet ls;
  ls.n = count - j0 < L ? count - j0 : L;
  for (int l = 0; l < L; ++l) {
    jx[l] = j0 + (l < ls.n ? l : ls.n - 1);
    ls.ix[l] = idx[jx[l]];
  }
  return ls;
}

// p = R m + t, as project() and backwardFrame() compute it.
inline void cameraSpace(const ProjectIn& in, const vf m[3], vf p[3]) {
  for (int r = 0; r < 3; ++r)
    p[r] = vs(in.R[r][0]) * m[0] + vs(in.R[r][1]) * m[1] + vs(in.R[r][2]) * m[2] + vs(in.t[r]);
}

// quatToRot: the normalised quaternion (w, x, y, z; the identity where |q| <= 1e-12), |q|
// and the rotation matrix.
struct QuatLanes {
  vf w, x, y, z, norm;
  vi ok;  // |q| > 1e-12
  vf R[3][3];
};
inline QuatLanes quatLanes(const LaneSet& ls, const float* rotations) {
  const vf one = vs(1.0f), zero = vs(0.0f), two = vs(2.0f);
  const vf q0 = ls.at(rotations, 4, 0), q1 = ls.at(rotations, 4, 1), q2 = ls.at(rotations, 4, 2),
           q3 = ls.at(rotations, 4, 3);
  QuatLanes q;
  q.norm = vsqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3);
  q.ok = q.norm > vs(1e-12f);
  q.w = q.ok ? q0 / q.norm : one;
  q.x = q.ok ? q1 / q.norm : zero;
  q.y = q.ok ? q2 / q.norm : zero;
  q.z = q.ok ? q3 / q.norm : zero;
  const vf w = q.w, x = q.x, y = q.y, z = q.z;
  q.R[0][0] = one - two * (y * y + z * z);
  q.R[0][1] = two * (x * y - w * z);
  q.R[0][2] = two * (x * z + w * y);
  q.R[1][0] = two * (x * y + w * z);
  q.R[1][1] = one - two * (x * x + z * z);
  q.R[1][2] = two * (y * z - w * x);
  q.R[2][0] = two * (x * z - w * y);
  q.R[2][1] = two * (y * z + w * x);
  q.R[2][2] = one - two * (x * x + y * y);
  return q;
}

// The scales (safeExp of the log-scales), M = Rq diag(sc) and Sigma = M M^T.
inline void covarianceLanes(const LaneSet& ls, const float* log_scales, const QuatLanes& q, vf sc[3], vf M[3][3],
                            vf Sig[3][3]) {
  for (int k = 0; k < 3; ++k) sc[k] = lanesExp(clampLanes(ls.at(log_scales, 3, k), -60.0f, 60.0f));
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) M[r][k] = q.R[r][k] * sc[k];
  for (int r = 0; r < 3; ++r)
    for (int k = r; k < 3; ++k) Sig[r][k] = Sig[k][r] = M[r][0] * M[k][0] + M[r][1] * M[k][1] + M[r][2] * M[k][2];
}

// A = J W from J's non-zero entries, its zero entries included (0 x R is +-0, and its
// sign reaches A).
inline void jacobianTimesW(const ProjectIn& in, vf J00, vf J02, vf J11, vf J12, vf A[2][3]) {
  for (int k = 0; k < 3; ++k) {
    A[0][k] = J00 * vs(in.R[0][k]) + vs(0.0f * in.R[1][k]) + J02 * vs(in.R[2][k]);
    A[1][k] = vs(0.0f * in.R[0][k]) + J11 * vs(in.R[1][k]) + J12 * vs(in.R[2][k]);
  }
}

// viewBasis: the unit direction from the camera centre (zero where the mean is the
// centre), its distance, and the SH basis of the active degree.
inline vf viewBasisLanes(const ProjectIn& in, const vf m[3], vf d[3], vf basis[16]) {
  using namespace sh_constants;
  const vf zero = vs(0.0f), two = vs(2.0f);
  for (int k = 0; k < 3; ++k) d[k] = m[k] - vs(in.center[k]);
  const vf dn = vsqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  for (int k = 0; k < 3; ++k) d[k] = dn > zero ? d[k] / dn : zero;
  const int degree = in.sh_degree;
  basis[0] = vs(kProjShC0);
  if (degree >= 1) {
    const float c1 = static_cast<float>(C1);
    basis[1] = vs(-c1) * d[1];
    basis[2] = vs(c1) * d[2];
    basis[3] = vs(-c1) * d[0];
  }
  if (degree >= 2) {
    const vf X = d[0], Y = d[1], Z = d[2];
    const vf xx = X * X, yy = Y * Y, zz = Z * Z, xy = X * Y, yz = Y * Z, xz = X * Z;
    basis[4] = vs(static_cast<float>(C2[0])) * xy;
    basis[5] = vs(static_cast<float>(C2[1])) * yz;
    basis[6] = vs(static_cast<float>(C2[2])) * (two * zz - xx - yy);
    basis[7] = vs(static_cast<float>(C2[3])) * xz;
    basis[8] = vs(static_cast<float>(C2[4])) * (xx - yy);
    if (degree >= 3) {
      const vf three = vs(3.0f), four = vs(4.0f);
      basis[9] = vs(static_cast<float>(C3[0])) * Y * (three * xx - yy);
      basis[10] = vs(static_cast<float>(C3[1])) * xy * Z;
      basis[11] = vs(static_cast<float>(C3[2])) * Y * (four * zz - xx - yy);
      basis[12] = vs(static_cast<float>(C3[3])) * Z * (two * zz - three * xx - three * yy);
      basis[13] = vs(static_cast<float>(C3[4])) * X * (four * zz - xx - yy);
      basis[14] = vs(static_cast<float>(C3[5])) * Z * (xx - yy);
      basis[15] = vs(static_cast<float>(C3[6])) * X * (xx - three * yy);
    }
  }
  return dn;
}

// backwardFrame: what projectBackward recomputes of project() (projection.h).
struct FrameLanes {
  vf p[3], iz, iz2, d[3], dn, basis[16];
  QuatLanes q;
  vf sc[3], M[3][3], Sig[3][3], A[2][3];
};
inline FrameLanes frameLanes(const ProjectIn& in, const LaneSet& ls) {
  FrameLanes f;
  const vf m[3] = {ls.at(in.means, 3, 0), ls.at(in.means, 3, 1), ls.at(in.means, 3, 2)};
  cameraSpace(in, m, f.p);
  f.iz = vs(1.0f) / f.p[2];
  f.iz2 = f.iz * f.iz;
  f.dn = viewBasisLanes(in, m, f.d, f.basis);
  f.q = quatLanes(ls, in.rotations);
  covarianceLanes(ls, in.log_scales, f.q, f.sc, f.M, f.Sig);
  jacobianTimesW(in, vs(in.fx) * f.iz, vs(-in.fx) * f.p[0] * f.iz2, vs(in.fy) * f.iz, vs(-in.fy) * f.p[1] * f.iz2, f.A);
  return f;
}

// colorBackward's view-direction part: the mean's gradient dm through the SH basis and
// the normalisation, for the colour gradients dc (zero where clamped); zero at SH degree
// 0 and where the mean is the camera centre.
inline void viewDirectionGrad(const ProjectIn& in, const LaneSet& ls, const FrameLanes& f, const vf dc[3], vf dm[3]) {
  using namespace sh_constants;
  const vf zero = vs(0.0f);
  const std::size_t stride = static_cast<std::size_t>(in.sh_stride);
  const int degree = in.sh_degree, active = (degree + 1) * (degree + 1);
  dm[0] = dm[1] = dm[2] = zero;
  if (degree <= 0) return;
  vf gb[16];
  for (int k = 0; k < active; ++k) {
    const std::size_t o3 = static_cast<std::size_t>(k * 3);
    gb[k] =
        dc[0] * ls.at(in.sh, stride, o3) + dc[1] * ls.at(in.sh, stride, o3 + 1) + dc[2] * ls.at(in.sh, stride, o3 + 2);
  }
  const vf x = f.d[0], y = f.d[1], z = f.d[2];
  const float c1 = static_cast<float>(C1);
  vf gd[3];
  gd[0] = zero + vs(-c1) * gb[3];
  gd[1] = zero + vs(-c1) * gb[1];
  gd[2] = zero + vs(c1) * gb[2];
  if (degree > 1) {
    const float c20 = static_cast<float>(C2[0]), c21 = static_cast<float>(C2[1]), c22 = static_cast<float>(C2[2]),
                c23 = static_cast<float>(C2[3]), c24 = static_cast<float>(C2[4]);
    gd[0] = gd[0] + (vs(c20) * y * gb[4] - vs(2 * c22) * x * gb[6] + vs(c23) * z * gb[7] + vs(2 * c24) * x * gb[8]);
    gd[1] = gd[1] + (vs(c20) * x * gb[4] + vs(c21) * z * gb[5] - vs(2 * c22) * y * gb[6] - vs(2 * c24) * y * gb[8]);
    gd[2] = gd[2] + (vs(c21) * y * gb[5] + vs(4 * c22) * z * gb[6] + vs(c23) * x * gb[7]);
  }
  if (degree > 2) {
    const vf xx = x * x, yy = y * y, zz = z * z;
    const vf three = vs(3.0f), four = vs(4.0f), six = vs(6.0f);
    const float c30 = static_cast<float>(C3[0]), c31 = static_cast<float>(C3[1]), c32 = static_cast<float>(C3[2]),
                c33 = static_cast<float>(C3[3]), c34 = static_cast<float>(C3[4]), c35 = static_cast<float>(C3[5]),
                c36 = static_cast<float>(C3[6]);
    gd[0] = gd[0] + (vs(6 * c30) * x * y * gb[9] + vs(c31) * y * z * gb[10] - vs(2 * c32) * x * y * gb[11] -
                     vs(6 * c33) * x * z * gb[12] + vs(c34) * (four * zz - three * xx - yy) * gb[13] +
                     vs(2 * c35) * x * z * gb[14] + vs(c36) * (three * xx - three * yy) * gb[15]);
    gd[1] = gd[1] + (vs(c30) * (three * xx - three * yy) * gb[9] + vs(c31) * x * z * gb[10] +
                     vs(c32) * (four * zz - xx - three * yy) * gb[11] - vs(6 * c33) * y * z * gb[12] -
                     vs(2 * c34) * x * y * gb[13] - vs(2 * c35) * y * z * gb[14] - vs(6 * c36) * x * y * gb[15]);
    gd[2] = gd[2] + (vs(c31) * x * y * gb[10] + vs(8 * c32) * y * z * gb[11] +
                     vs(c33) * (six * zz - three * xx - three * yy) * gb[12] + vs(8 * c34) * x * z * gb[13] +
                     vs(c35) * (xx - yy) * gb[14]);
  }
  const vf dot = gd[0] * f.d[0] + gd[1] * f.d[1] + gd[2] * f.d[2];
  const vi away = f.dn > zero;
  for (int r = 0; r < 3; ++r) dm[r] = away ? zero + (gd[r] - f.d[r] * dot) / f.dn : zero;
}

// Rule 1's frustum test alone (the first of project()'s culls, the same operations) for
// the L Gaussians of ls.
inline vi inFrustum(const ProjectIn& in, const LaneSet& ls) {
  const vf m[3] = {ls.at(in.means, 3, 0), ls.at(in.means, 3, 1), ls.at(in.means, 3, 2)};
  vf p[3];
  cameraSpace(in, m, p);
  const vf xz = p[0] / p[2], yz = p[1] / p[2];
  return (p[2] >= vs(in.near_plane)) & (absLanes(xz - vs(in.gx_mid)) <= vs(in.gx_half)) &
         (absLanes(yz - vs(in.gy_mid)) <= vs(in.gy_half));
}

// Rules 1-5 for the Gaussians listed in ls (its first ls.n lanes written to out).
void projectLanes(const ProjectIn& in, const LaneSet& ls, projection::Projected<float>* out);

// Two passes per block of up to kProjectBlock Gaussians: the frustum test for all, then
// the whole projection for those it keeps, gathered eight at a time (most of a room's
// Gaussians are outside a view's frustum, and a lane computes its Gaussian's every value
// whether or not an earlier cull rejects it). The others are written visible = false, as
// project() leaves them.
void projectRange(const ProjectIn& in, std::size_t begin, std::size_t end, projection::Projected<float>* out) {
  constexpr std::size_t kProjectBlock = 256;
  std::uint32_t kept[kProjectBlock];
  for (std::size_t b = begin; b < end; b += kProjectBlock) {
    const std::size_t e = end - b < kProjectBlock ? end : b + kProjectBlock;
    int nk = 0;
    for (std::size_t i0 = b; i0 < e; i0 += L) {
      LaneSet ls;
      ls.n = e - i0 < static_cast<std::size_t>(L) ? static_cast<int>(e - i0) : L;
      for (int l = 0; l < L; ++l) ls.ix[l] = i0 + static_cast<std::size_t>(l < ls.n ? l : ls.n - 1);
      const vi keep = inFrustum(in, ls);
      for (int l = 0; l < ls.n; ++l) {
        out[ls.ix[l]].visible = false;
        if (keep[l]) kept[nk++] = static_cast<std::uint32_t>(ls.ix[l] - b);
      }
    }
    for (int j0 = 0; j0 < nk; j0 += L) {
      LaneSet ls;
      ls.n = nk - j0 < L ? nk - j0 : L;
      for (int l = 0; l < L; ++l) ls.ix[l] = b + kept[j0 + (l < ls.n ? l : ls.n - 1)];
      projectLanes(in, ls, out);
    }
  }
}

void projectLanes(const ProjectIn& in, const LaneSet& ls, projection::Projected<float>* out) {
  const std::size_t stride = static_cast<std::size_t>(in.sh_stride);
  const int active = (in.sh_degree + 1) * (in.sh_degree + 1);
  const vf one = vs(1.0f), zero = vs(0.0f), two = vs(2.0f);
  {
    const int n = ls.n;
    const vf m[3] = {ls.at(in.means, 3, 0), ls.at(in.means, 3, 1), ls.at(in.means, 3, 2)};
    vf p[3];
    cameraSpace(in, m, p);
    vi vis = p[2] >= vs(in.near_plane);
    const vf xz = p[0] / p[2], yz = p[1] / p[2];
    vis &= (absLanes(xz - vs(in.gx_mid)) <= vs(in.gx_half)) & (absLanes(yz - vs(in.gy_mid)) <= vs(in.gy_half));
    const vf o = one / (one + lanesExp(-clampLanes(ls.at(in.opacities, 1, 0), -80.0f, 80.0f)));
    vis &= o >= vs(kMinA);

    const QuatLanes q = quatLanes(ls, in.rotations);
    vf sc[3], M[3][3], Sig[3][3];
    covarianceLanes(ls, in.log_scales, q, sc, M, Sig);
    const vf iz = one / p[2];
    vf A[2][3];
    jacobianTimesW(in, vs(in.fx) * iz, vs(-in.fx) * p[0] * iz * iz, vs(in.fy) * iz, vs(-in.fy) * p[1] * iz * iz, A);
    vf AS[2][3];
    for (int r = 0; r < 2; ++r)
      for (int k = 0; k < 3; ++k) AS[r][k] = A[r][0] * Sig[0][k] + A[r][1] * Sig[1][k] + A[r][2] * Sig[2][k];
    const vf eps = vs(in.eps2d);
    const vf ca = AS[0][0] * A[0][0] + AS[0][1] * A[0][1] + AS[0][2] * A[0][2] + eps;
    const vf cb = AS[0][0] * A[1][0] + AS[0][1] * A[1][1] + AS[0][2] * A[1][2];
    const vf cc = AS[1][0] * A[1][0] + AS[1][1] * A[1][1] + AS[1][2] * A[1][2] + eps;
    const vf det = ca * cc - cb * cb;
    vis &= (det > zero) & finiteLanes(det);
    const vf mx = vs(in.fx) * xz + vs(in.cx), my = vs(in.fy) * yz + vs(in.cy);
    const vf conic_a = cc / det, conic_b = -cb / det, conic_c = ca / det;
    // Rule 4, the opacity-aware extent.
    const vf k2 = two * lanesLog(vs(255.0f) * o);
    const vf hx = vsqrt(maxZeroLanes(k2 * ca)), hy = vsqrt(maxZeroLanes(k2 * cc));
    const vf radius = hx < hy ? hy : hx;
    vis &= ~((mx + hx < zero) | (mx - hx > vs(in.width)) | (my + hy < zero) | (my - hy > vs(in.height)) |
             ~finiteLanes(radius));

    // Rule 5: the colour along the view direction.
    vf d[3], basis[16];
    viewBasisLanes(in, m, d, basis);
    vf col[3];
    vi clamped[3] = {};
    for (int c = 0; c < 3; ++c) {
      vf v = vs(0.5f);
      for (int k = 0; k < active; ++k) v = v + basis[k] * ls.at(in.sh, stride, static_cast<std::size_t>(k * 3 + c));
      clamped[c] = v < zero;
      col[c] = clamped[c] ? zero : v;
    }

    for (int l = 0; l < n; ++l) {
      projection::Projected<float>& P = out[ls.ix[l]];
      P.visible = vis[l] != 0;
      P.mean2d[0] = mx[l];
      P.mean2d[1] = my[l];
      P.conic[0] = conic_a[l];
      P.conic[1] = conic_b[l];
      P.conic[2] = conic_c[l];
      P.cov2d[0] = ca[l];
      P.cov2d[1] = cb[l];
      P.cov2d[2] = cc[l];
      P.depth = p[2][l];
      P.opacity = o[l];
      for (int c = 0; c < 3; ++c) {
        P.color[c] = col[c][l];
        P.clamped[c] = clamped[c][l] != 0;
      }
      P.half[0] = hx[l];
      P.half[1] = hy[l];
      P.radius = radius[l];
    }
  }
}

// projectBackward<float> (projection.h: backwardFrame, then colorBackward, conicBackward,
// mean2dBackward, cameraToMean, scaleBackward and the rotation) for L Gaussians at a time,
// every lane in the scalar code's order; where the scalar code skips a stage (a Gaussian
// at the camera centre, a clamped scale, a zero quaternion) the lane's result is not added.
void projectBackwardList(const ProjectIn& in, const std::uint32_t* idx, int count,
                         const projection::Projected<float>* proj, const projection::ProjectedGrad<float>* dP,
                         const ProjectGradOut& out) {
  using namespace sh_constants;
  const std::size_t stride = static_cast<std::size_t>(in.sh_stride);
  const int degree = in.sh_degree, active = (degree + 1) * (degree + 1);
  const vf one = vs(1.0f), zero = vs(0.0f), two = vs(2.0f);
  for (int j0 = 0; j0 < count; j0 += L) {
    int jx[L];
    const LaneSet ls = listLanes(idx, count, j0, jx);
    const int n = ls.n;
    vf Pa{}, Pb{}, Pc{}, Po{}, dPo{}, dmx{}, dmy{}, dca{}, dcb{}, dcc{}, dcol[3];
    vi clamped[3];
    float dcol_l[3][L];
    std::int32_t clamped_l[3][L];
    for (int l = 0; l < L; ++l) {
      const projection::Projected<float>& P = proj[ls.ix[l]];
      const projection::ProjectedGrad<float>& g = dP[jx[l]];
      Pa[l] = P.conic[0];
      Pb[l] = P.conic[1];
      Pc[l] = P.conic[2];
      Po[l] = P.opacity;
      for (int c = 0; c < 3; ++c) {
        clamped_l[c][l] = P.clamped[c] ? -1 : 0;
        dcol_l[c][l] = g.color[c];
      }
      dPo[l] = g.opacity;
      dmx[l] = g.mean2d[0];
      dmy[l] = g.mean2d[1];
      dca[l] = g.conic[0];
      dcb[l] = g.conic[1];
      dcc[l] = g.conic[2];
    }
    for (int c = 0; c < 3; ++c) {
      std::memcpy(&dcol[c], dcol_l[c], sizeof(vf));
      std::memcpy(&clamped[c], clamped_l[c], sizeof(vi));
    }

    const FrameLanes f = frameLanes(in, ls);
    const vf(&p)[3] = f.p;
    const vf iz = f.iz, iz2 = f.iz2;
    const vf(&M)[3][3] = f.M;
    const vf(&Sig)[3][3] = f.Sig;
    const vf(&A)[2][3] = f.A;
    const vf(&sc)[3] = f.sc;
    const QuatLanes& q = f.q;
    const vf(&basis)[16] = f.basis;

    // The opacity logit.
    const vf g_opacity = dPo * Po * (one - Po);

    // colorBackward.
    vf dc[3];
    for (int c = 0; c < 3; ++c) dc[c] = clamped[c] ? zero : dcol[c];
    vf dm[3];
    viewDirectionGrad(in, ls, f, dc, dm);

    // conicBackward.
    const vf gQ00 = dca, gQ01 = vs(0.5f) * dcb, gQ11 = dcc;
    const vf t00 = Pa * gQ00 + Pb * gQ01, t01 = Pa * gQ01 + Pb * gQ11;
    const vf t10 = Pb * gQ00 + Pc * gQ01, t11 = Pb * gQ01 + Pc * gQ11;
    const vf G00 = -(t00 * Pa + t01 * Pb), G01 = -(t00 * Pb + t01 * Pc), G11 = -(t10 * Pb + t11 * Pc);
    const vf G2[2][2] = {{G00, G01}, {G01, G11}};
    vf G2A[2][3];
    for (int r = 0; r < 2; ++r)
      for (int k = 0; k < 3; ++k) G2A[r][k] = G2[r][0] * A[0][k] + G2[r][1] * A[1][k];
    vf gSig[3][3];
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) gSig[r][k] = A[0][r] * G2A[0][k] + A[1][r] * G2A[1][k];
    vf gA[2][3];
    for (int r = 0; r < 2; ++r)
      for (int k = 0; k < 3; ++k)
        gA[r][k] = two * (G2A[r][0] * Sig[0][k] + G2A[r][1] * Sig[1][k] + G2A[r][2] * Sig[2][k]);
    // gJ's entries (0, 0), (0, 2), (1, 1) and (1, 2): the ones p reaches.
    auto gJ = [&](int r, int k) {
      return gA[r][0] * vs(in.R[k][0]) + gA[r][1] * vs(in.R[k][1]) + gA[r][2] * vs(in.R[k][2]);
    };
    const vf gJ00 = gJ(0, 0), gJ02 = gJ(0, 2), gJ11 = gJ(1, 1), gJ12 = gJ(1, 2);
    const vf fx_iz2 = vs(-in.fx) * iz2, fy_iz2 = vs(-in.fy) * iz2;
    vf gp[3];
    gp[0] = gJ02 * fx_iz2;
    gp[1] = gJ12 * fy_iz2;
    gp[2] = gJ00 * fx_iz2 + gJ02 * (vs(2.0f * in.fx) * p[0] * iz2 * iz) + gJ11 * fy_iz2 +
            gJ12 * (vs(2.0f * in.fy) * p[1] * iz2 * iz);
    vf gM[3][3];
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) gM[r][k] = two * (gSig[r][0] * M[0][k] + gSig[r][1] * M[1][k] + gSig[r][2] * M[2][k]);

    // mean2dBackward, then cameraToMean.
    gp[0] = gp[0] + dmx * vs(in.fx) * iz;
    gp[1] = gp[1] + dmy * vs(in.fy) * iz;
    gp[2] = gp[2] - dmx * vs(in.fx) * p[0] * iz2 - dmy * vs(in.fy) * p[1] * iz2;
    vf g_mean[3];
    for (int k = 0; k < 3; ++k)
      g_mean[k] = vs(in.R[0][k]) * gp[0] + vs(in.R[1][k]) * gp[1] + vs(in.R[2][k]) * gp[2] + dm[k];

    // scaleBackward.
    vf g_scale[3];
    vi scale_live[3];
    for (int k = 0; k < 3; ++k) {
      const vf gs = q.R[0][k] * gM[0][k] + q.R[1][k] * gM[1][k] + q.R[2][k] * gM[2][k];
      const vf raw = ls.at(in.log_scales, 3, static_cast<std::size_t>(k));
      scale_live[k] = (raw > vs(-60.0f)) & (raw < vs(60.0f));
      g_scale[k] = gs * sc[k];
    }

    // The rotation, through the normalisation q / |q|.
    vf gR[3][3];
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) gR[r][k] = gM[r][k] * sc[k];
    const vf w = q.w, x = q.x, y = q.y, z = q.z;
    vf gq[4];
    gq[0] = two * (-z * gR[0][1] + y * gR[0][2] + z * gR[1][0] - x * gR[1][2] - y * gR[2][0] + x * gR[2][1]);
    gq[1] = two * (y * gR[0][1] + z * gR[0][2] + y * gR[1][0] - two * x * gR[1][1] - w * gR[1][2] + z * gR[2][0] +
                   w * gR[2][1] - two * x * gR[2][2]);
    gq[2] = two * (vs(-2.0f) * y * gR[0][0] + x * gR[0][1] + w * gR[0][2] + x * gR[1][0] + z * gR[1][2] - w * gR[2][0] +
                   z * gR[2][1] - two * y * gR[2][2]);
    gq[3] = two * (vs(-2.0f) * z * gR[0][0] - w * gR[0][1] + x * gR[0][2] + w * gR[1][0] - two * z * gR[1][1] +
                   y * gR[1][2] + x * gR[2][0] + y * gR[2][1]);
    const vf qdot = gq[0] * w + gq[1] * x + gq[2] * y + gq[3] * z;
    const vf qv[4] = {w, x, y, z};
    vf g_rot[4];
    for (int k = 0; k < 4; ++k) g_rot[k] = (gq[k] - qv[k] * qdot) / q.norm;

    // The colour's SH coefficients, and every sum added to the Gaussian's gradients.
    for (int l = 0; l < n; ++l) {
      const std::size_t i = ls.ix[l];
      out.opacities[i] += g_opacity[l];
      float* gsh = out.sh + i * stride;
      for (int k = 0; k < active; ++k)
        for (int c = 0; c < 3; ++c) gsh[k * 3 + c] += dc[c][l] * basis[k][l];
      for (int k = 0; k < 3; ++k) out.means[3 * i + k] += g_mean[k][l];
      for (int k = 0; k < 3; ++k)
        if (scale_live[k][l]) out.log_scales[3 * i + k] += g_scale[k][l];
      if (q.ok[l])
        for (int k = 0; k < 4; ++k) out.rotations[4 * i + k] += g_rot[k][l];
    }
  }
}

// squaredGradientsFloat's per-Gaussian stage (fisher_pass.cpp) for L Gaussians at a time:
// backwardFrame and projectJacobian<float> (projection.h) lane by lane in their order,
// then the quadratic forms of the tile moments in double, L double lanes (the scalar code's
// operations, in its order), and the squared gradients added as the scalar stage adds them.
void fisherChainList(const ProjectIn& in, const std::uint32_t* idx, int count, const projection::Projected<float>* proj,
                     const double* moments, const FisherGradOut& out) {
  typedef double vd __attribute__((vector_size(8 * L)));
  const std::size_t stride = static_cast<std::size_t>(in.sh_stride);
  const int active = (in.sh_degree + 1) * (in.sh_degree + 1);
  const vf zero = vs(0.0f), one = vs(1.0f);
  // (Conversions and broadcasts written in place: a lambda returning vd, wider than the
  // target's vectors, draws GCC's ABI note.)
  for (int j0 = 0; j0 < count; j0 += L) {
    int jx[L];
    const LaneSet ls = listLanes(idx, count, j0, jx);
    const int n = ls.n;
    vf Pa{}, Pb{}, Pc{}, Po{};
    vi clamped[3] = {};
    for (int l = 0; l < L; ++l) {
      const projection::Projected<float>& P = proj[ls.ix[l]];
      Pa[l] = P.conic[0];
      Pb[l] = P.conic[1];
      Pc[l] = P.conic[2];
      Po[l] = P.opacity;
      for (int c = 0; c < 3; ++c) clamped[c][l] = P.clamped[c] ? -1 : 0;
    }
    const FrameLanes f = frameLanes(in, ls);

    // projectJacobian: J[r][0..2] the means', J[r][3..5] the log-scales' row r.
    vf J[6][6];
    for (int r = 0; r < 6; ++r)
      for (int k = 0; k < 6; ++k) J[r][k] = zero;
    // cameraToMean onto a zero row: 0 + (R^T gp + dm).
    auto toMean = [&](const vf gp[3], const vf dm[3], vf row[6]) {
      for (int k = 0; k < 3; ++k)
        row[k] = row[k] + (vs(in.R[0][k]) * gp[0] + vs(in.R[1][k]) * gp[1] + vs(in.R[2][k]) * gp[2] + dm[k]);
    };
    const vf zero3[3] = {zero, zero, zero};
    for (int r = 0; r < 2; ++r) {
      const vf d0 = r == 0 ? one : zero, d1 = r == 1 ? one : zero;
      vf gp[3];
      gp[0] = zero + d0 * vs(in.fx) * f.iz;
      gp[1] = zero + d1 * vs(in.fy) * f.iz;
      gp[2] = zero - d0 * vs(in.fx) * f.p[0] * f.iz2 - d1 * vs(in.fy) * f.p[1] * f.iz2;
      toMean(gp, zero3, J[r]);
    }
    const vf qm[2][2] = {{Pa, Pb}, {Pb, Pc}};
    vf rA[2][3], wR[2][3], tR[2][3];
    for (int j = 0; j < 2; ++j) {
      for (int k = 0; k < 3; ++k) rA[j][k] = qm[j][0] * f.A[0][k] + qm[j][1] * f.A[1][k];
      vf sS[3];
      for (int k = 0; k < 3; ++k) sS[k] = f.Sig[k][0] * rA[j][0] + f.Sig[k][1] * rA[j][1] + f.Sig[k][2] * rA[j][2];
      for (int k = 0; k < 3; ++k) wR[j][k] = vs(in.R[k][0]) * sS[0] + vs(in.R[k][1]) * sS[1] + vs(in.R[k][2]) * sS[2];
      for (int k = 0; k < 3; ++k) tR[j][k] = f.q.R[0][k] * rA[j][0] + f.q.R[1][k] * rA[j][1] + f.q.R[2][k] * rA[j][2];
    }
    vi scale_live[3];
    for (int k = 0; k < 3; ++k) {
      const vf raw = ls.at(in.log_scales, 3, static_cast<std::size_t>(k));
      scale_live[k] = (raw > vs(-60.0f)) & (raw < vs(60.0f));
    }
    const int uv[3][2] = {{0, 0}, {0, 1}, {1, 1}};
    const vf fx_iz2 = vs(-in.fx) * f.iz2, fy_iz2 = vs(-in.fy) * f.iz2;
    for (int r = 0; r < 3; ++r) {
      const int u = uv[r][0], v = uv[r][1];
      vf gJ[2][3];
      for (int row = 0; row < 2; ++row)
        for (int k = 0; k < 3; ++k) gJ[row][k] = -(qm[u][row] * wR[v][k] + qm[v][row] * wR[u][k]);
      vf gp[3];
      gp[0] = gJ[0][2] * fx_iz2;
      gp[1] = gJ[1][2] * fy_iz2;
      gp[2] = gJ[0][0] * fx_iz2 + gJ[0][2] * (vs(2.0f * in.fx) * f.p[0] * f.iz2 * f.iz) + gJ[1][1] * fy_iz2 +
              gJ[1][2] * (vs(2.0f * in.fy) * f.p[1] * f.iz2 * f.iz);
      toMean(gp, zero3, J[2 + r]);
      for (int k = 0; k < 3; ++k)
        J[2 + r][3 + k] = scale_live[k] ? vs(-2.0f) * f.sc[k] * f.sc[k] * tR[u][k] * tR[v][k] : zero;
    }
    vf dc[3], dm[3];
    for (int c = 0; c < 3; ++c) dc[c] = clamped[c] ? zero : one;
    viewDirectionGrad(in, ls, f, dc, dm);
    toMean(zero3, dm, J[5]);

    // The quadratic forms, in double.
    vd mo[kFisherSlot];
    for (int m = 0; m < kFisherSlot; ++m)
      for (int l = 0; l < L; ++l) mo[m][l] = moments[static_cast<std::size_t>(jx[l]) * kFisherSlot + m];
    const vd a = __builtin_convertvector(Pa, vd), b = __builtin_convertvector(Pb, vd),
             c = __builtin_convertvector(Pc, vd), o = __builtin_convertvector(Po, vd);
    const vd E[5][5] = {{mo[kE20], mo[kE11], mo[kE30], mo[kE21], mo[kE12]},
                        {mo[kE11], mo[kE02], mo[kE21], mo[kE12], mo[kE03]},
                        {mo[kE30], mo[kE21], mo[kE40], mo[kE31], mo[kE22]},
                        {mo[kE21], mo[kE12], mo[kE31], mo[kE22], mo[kE13]},
                        {mo[kE12], mo[kE03], mo[kE22], mo[kE13], mo[kE04]}};
    const vd F[5] = {mo[kF10], mo[kF01], mo[kF20], mo[kF11], mo[kF02]};
    vd res[6];
    for (int p = 0; p < 6; ++p) {
      const vd J0 = __builtin_convertvector(J[0][p], vd), J1 = __builtin_convertvector(J[1][p], vd);
      const vd k[5] = {a * J0 + b * J1, b * J0 + c * J1, (-0.5 - vd{}) * __builtin_convertvector(J[2][p], vd),
                       -__builtin_convertvector(J[3][p], vd), (-0.5 - vd{}) * __builtin_convertvector(J[4][p], vd)};
      vd quad = (0.0 - vd{}), lin = (0.0 - vd{});
      for (int u = 0; u < 5; ++u) {
        vd row = (0.0 - vd{});
        for (int v = 0; v < 5; ++v) row = row + E[u][v] * k[v];
        quad = quad + k[u] * row;
        lin = lin + k[u] * F[u];
      }
      const vd jc = __builtin_convertvector(J[5][p], vd);
      const vd val = o * o * quad + (2.0 - vd{}) * o * jc * lin + jc * jc * mo[kW];
      res[p] = (0.0 - vd{}) < val ? val : (0.0 - vd{});  // std::max(0.0, val)
    }
    const vd dlogit = o * ((1.0 - vd{}) - o);
    const vd g_opacity = dlogit * dlogit * mo[kE00];
    vd g_sh[16];
    for (int k = 0; k < active; ++k) {
      const vd y = __builtin_convertvector(f.basis[k], vd);
      g_sh[k] = mo[kW] * y * y;
    }
    for (int l = 0; l < n; ++l) {
      const std::size_t i = ls.ix[l];
      for (int p = 0; p < 3; ++p) out.means[3 * i + p] += static_cast<float>(res[p][l]);
      for (int p = 0; p < 3; ++p) out.log_scales[3 * i + p] += static_cast<float>(res[3 + p][l]);
      out.opacities[i] += static_cast<float>(g_opacity[l]);
      float* gsh = out.sh + i * stride;
      for (int k = 0; k < active; ++k)
        for (int ch = 0; ch < 3; ++ch)
          if (!clamped[ch][l]) gsh[k * 3 + ch] += static_cast<float>(g_sh[k][l]);
    }
  }
}

}  // namespace
}  // namespace saresgs::raster_kernels
