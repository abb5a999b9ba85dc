// The projection kernels (rules 1-5, splat/raster/raster_kernels.h's projectRange):
// projection::project<float> with the opacity-aware extent, SARESGS_KERNEL_LANES Gaussians
// at a time. Included right after splat/raster/raster_kernels_impl.h in the same
// translation unit, with the same SARESGS_KERNEL_NS / SARESGS_KERNEL_LANES, and uses its
// vector types.
//
// Bit for bit project<float>: every lane runs project()'s operations in its order, each
// correctly rounded (no FMA contraction here or there; sqrt and division are IEEE in both),
// the zero entries of J included (0 x R is +-0 and its sign reaches A), and the
// exponentials and the logarithm are libm's expf and logf, called lane by lane, as the
// scalar code calls them. Where project() returns early (a cull) a lane carries on with
// the values it has and ends with visible = false. Tests: ProjectKernels.*
// (tests/splat/raster/test_project_kernels.cpp).
#if !defined(SARESGS_KERNEL_NS) || !defined(SARESGS_KERNEL_LANES)
#error "include raster_kernels_impl.h (with its macros) before project_kernels_impl.h"
#endif

#include "splat/raster/sh_constants.h"

namespace saresgs::raster_kernels::SARESGS_KERNEL_NS {
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

constexpr float kProjShC0 = 0.28209479177387814f;  // splat/gaussians.h's kShC0 (rasterizer.cpp checks)

}  // namespace

void projectRange(const ProjectIn& in, std::size_t begin, std::size_t end, projection::Projected<float>* out) {
  using namespace sh_constants;
  const std::size_t stride = static_cast<std::size_t>(in.sh_stride);
  const int degree = in.sh_degree, active = (degree + 1) * (degree + 1);
  const vf one = vs(1.0f), zero = vs(0.0f), two = vs(2.0f);
  for (std::size_t i0 = begin; i0 < end; i0 += L) {
    const int n = end - i0 < static_cast<std::size_t>(L) ? static_cast<int>(end - i0) : L;
    std::size_t ix[L];
    for (int l = 0; l < L; ++l) ix[l] = i0 + static_cast<std::size_t>(l < n ? l : n - 1);
    auto lanes = [&](const float* a, std::size_t per, std::size_t off) {
      vf v;
      for (int l = 0; l < L; ++l) v[l] = a[ix[l] * per + off];
      return v;
    };
    const vf m[3] = {lanes(in.means, 3, 0), lanes(in.means, 3, 1), lanes(in.means, 3, 2)};
    vf p[3];
    for (int r = 0; r < 3; ++r)
      p[r] = vs(in.R[r][0]) * m[0] + vs(in.R[r][1]) * m[1] + vs(in.R[r][2]) * m[2] + vs(in.t[r]);
    vi vis = p[2] >= vs(in.near_plane);
    const vf xz = p[0] / p[2], yz = p[1] / p[2];
    vis &= (absLanes(xz - vs(in.gx_mid)) <= vs(in.gx_half)) & (absLanes(yz - vs(in.gy_mid)) <= vs(in.gy_half));
    const vf o = one / (one + lanesExp(-clampLanes(lanes(in.opacities, 1, 0), -80.0f, 80.0f)));
    vis &= o >= vs(kMinA);

    // quatToRot.
    const vf q0 = lanes(in.rotations, 4, 0), q1 = lanes(in.rotations, 4, 1), q2 = lanes(in.rotations, 4, 2),
             q3 = lanes(in.rotations, 4, 3);
    const vf qn = vsqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3);
    const vi qok = qn > vs(1e-12f);
    const vf w = qok ? q0 / qn : one, x = qok ? q1 / qn : zero, y = qok ? q2 / qn : zero, z = qok ? q3 / qn : zero;
    vf Rq[3][3];
    Rq[0][0] = one - two * (y * y + z * z);
    Rq[0][1] = two * (x * y - w * z);
    Rq[0][2] = two * (x * z + w * y);
    Rq[1][0] = two * (x * y + w * z);
    Rq[1][1] = one - two * (x * x + z * z);
    Rq[1][2] = two * (y * z - w * x);
    Rq[2][0] = two * (x * z - w * y);
    Rq[2][1] = two * (y * z + w * x);
    Rq[2][2] = one - two * (x * x + y * y);
    vf sc[3];
    for (int k = 0; k < 3; ++k) sc[k] = lanesExp(clampLanes(lanes(in.log_scales, 3, k), -60.0f, 60.0f));
    vf M[3][3];
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) M[r][k] = Rq[r][k] * sc[k];
    vf Sig[3][3];
    for (int r = 0; r < 3; ++r)
      for (int k = r; k < 3; ++k) Sig[r][k] = Sig[k][r] = M[r][0] * M[k][0] + M[r][1] * M[k][1] + M[r][2] * M[k][2];
    // A = J W, J's zero entries included (0 x R[1][k] and 0 x R[0][k]).
    const vf iz = one / p[2];
    const vf J00 = vs(in.fx) * iz, J02 = vs(-in.fx) * p[0] * iz * iz;
    const vf J11 = vs(in.fy) * iz, J12 = vs(-in.fy) * p[1] * iz * iz;
    vf A[2][3];
    for (int k = 0; k < 3; ++k) {
      A[0][k] = J00 * vs(in.R[0][k]) + vs(0.0f * in.R[1][k]) + J02 * vs(in.R[2][k]);
      A[1][k] = vs(0.0f * in.R[0][k]) + J11 * vs(in.R[1][k]) + J12 * vs(in.R[2][k]);
    }
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

    // Rule 5: viewBasis and the colour.
    vf d[3] = {m[0] - vs(in.center[0]), m[1] - vs(in.center[1]), m[2] - vs(in.center[2])};
    const vf dn = vsqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int k = 0; k < 3; ++k) d[k] = dn > zero ? d[k] / dn : zero;
    vf basis[16];
    basis[0] = vs(kProjShC0);
    if (degree >= 1) {
      const float c1 = static_cast<float>(C1);
      basis[1] = vs(-c1) * d[1];
      basis[2] = vs(c1) * d[2];
      basis[3] = vs(-c1) * d[0];
    }
    if (degree >= 2) {
      const vf X = d[0], Y = d[1], Z = d[2];
      const vf xx = X * X, yy = Y * Y, zz = Z * Z, xy = X * Y, yz = Y * Z, xz2 = X * Z;
      basis[4] = vs(static_cast<float>(C2[0])) * xy;
      basis[5] = vs(static_cast<float>(C2[1])) * yz;
      basis[6] = vs(static_cast<float>(C2[2])) * (two * zz - xx - yy);
      basis[7] = vs(static_cast<float>(C2[3])) * xz2;
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
    vf col[3];
    vi clamped[3];
    for (int c = 0; c < 3; ++c) {
      vf v = vs(0.5f);
      for (int k = 0; k < active; ++k) v = v + basis[k] * lanes(in.sh, stride, static_cast<std::size_t>(k * 3 + c));
      clamped[c] = v < zero;
      col[c] = clamped[c] ? zero : v;
    }

    for (int l = 0; l < n; ++l) {
      projection::Projected<float>& P = out[i0 + static_cast<std::size_t>(l)];
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

}  // namespace saresgs::raster_kernels::SARESGS_KERNEL_NS
