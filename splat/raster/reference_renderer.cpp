#include "splat/raster/reference_renderer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "splat/raster/sh.h"

namespace saresgs {

namespace {

// The contract's constants, in double (rasterize.h holds them as float).
constexpr double kMinAlphaD = 1.0 / 255.0;
constexpr double kMaxAlphaD = 0.99;
constexpr double kMinTransmittanceD = 1e-4;
constexpr double kMinCoverage = 1e-6;  // rule 7: depth is 0 below this accumulated alpha

double sigmoid(double x) {
  if (x >= 0) return 1.0 / (1.0 + std::exp(-x));
  const double e = std::exp(x);
  return e / (1.0 + e);
}

// Rotation matrix of the quaternion (w, x, y, z), normalised; zero reads as identity.
Eigen::Matrix3d rotationOf(const double* q_in) {
  double q[4] = {q_in[0], q_in[1], q_in[2], q_in[3]};
  // Scale by the largest component first so that tiny quaternions do not underflow.
  double big = 0;
  for (double v : q) big = std::max(big, std::abs(v));
  if (!(big > 0) || !std::isfinite(big)) return Eigen::Matrix3d::Identity();
  for (double& v : q) v /= big;
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  const double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
  Eigen::Matrix3d R;
  R << 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),  //
      2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),   //
      2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y);
  return R;
}

// One Gaussian after rules 1-5.
struct Projected {
  int index = 0;
  double z = 0;                   // camera-frame depth of the mean
  double mu_x = 0, mu_y = 0;      // 2D mean in pixels
  double ca = 0, cb = 0, cc = 0;  // inverse of Sigma2D: [[ca, cb], [cb, cc]]
  double hx = 0, hy = 0;          // half sizes of the screen rectangle
  double opacity = 0;
  double color[3] = {0, 0, 0};
};

void checkSize(const std::vector<double>& a, std::size_t expected, const char* name) {
  if (a.size() != expected)
    throw std::invalid_argument(std::string("referenceRender: ") + name + " has " + std::to_string(a.size()) +
                                " values, expected " + std::to_string(expected));
}

}  // namespace

ReferenceImage referenceRender(const GaussiansD& g, const Camera& cam, const RasterSettings& s,
                               std::span<const std::uint8_t> mask) {
  const std::size_t n = g.size();
  if (g.max_sh_degree < 0) throw std::invalid_argument("referenceRender: negative max_sh_degree");
  const int K = shCoeffCount(g.max_sh_degree);
  checkSize(g.means, 3 * n, "means");
  checkSize(g.log_scales, 3 * n, "log_scales");
  checkSize(g.rotations, 4 * n, "rotations");
  checkSize(g.sh, static_cast<std::size_t>(K) * 3 * n, "sh");
  if (!mask.empty() && mask.size() != n)
    throw std::invalid_argument("referenceRender: mask size differs from the model's");
  if (s.sh_degree < 0 || s.sh_degree > g.max_sh_degree)
    throw std::invalid_argument("referenceRender: active SH degree outside [0, max_sh_degree]");

  const int W = cam.K.width, H = cam.K.height;
  const double fx = cam.K.fx, fy = cam.K.fy, cx = cam.K.cx, cy = cam.K.cy;
  const double near_plane = s.near_plane, guard = s.guard_band, eps2d = s.eps2d;
  const Eigen::Matrix3d& Wr = cam.R;
  const Eigen::Vector3d centre = cam.center();

  ReferenceImage out;
  out.width = W;
  out.height = H;
  const std::size_t npix = static_cast<std::size_t>(std::max(W, 0)) * std::max(H, 0);
  out.rgb.assign(3 * npix, 0.0);
  out.alpha.assign(npix, 0.0);
  out.depth.assign(npix, 0.0);
  out.contributors.assign(npix, 0);
  out.radii.assign(n, 0.0);
  out.visible.assign(n, 0);

  // The frustum in x/z and y/z (rule 1), widened by the guard band about its centre.
  const double lx = -cx / fx, rx = (W - cx) / fx;
  const double ly = -cy / fy, ry = (H - cy) / fy;

  std::vector<Projected> kept;
  for (std::size_t i = 0; i < n; ++i) {
    // Rule 3 (with rule 8: a masked Gaussian has opacity 0).
    const double o = (!mask.empty() && mask[i] == 0) ? 0.0 : sigmoid(g.opacities[i]);
    if (!(o >= kMinAlphaD)) continue;

    // Rule 1.
    const Eigen::Vector3d m(g.means[3 * i], g.means[3 * i + 1], g.means[3 * i + 2]);
    const Eigen::Vector3d p = cam.R * m + cam.t;
    const double x = p.x(), y = p.y(), z = p.z();
    if (!(z >= near_plane) || !(z > 0)) continue;  // z > 0: projection needs it
    if (!(std::abs(x / z - 0.5 * (lx + rx)) <= guard * 0.5 * (rx - lx))) continue;
    if (!(std::abs(y / z - 0.5 * (ly + ry)) <= guard * 0.5 * (ry - ly))) continue;

    // Rule 2. Sigma = M M^T with M = R(q) S, so J W Sigma W^T J^T = A A^T, A = J W M.
    Eigen::Matrix3d M = rotationOf(&g.rotations[4 * i]);
    for (int k = 0; k < 3; ++k) M.col(k) *= std::exp(g.log_scales[3 * i + k]);
    Eigen::Matrix<double, 2, 3> J;
    J << fx / z, 0, -fx * x / (z * z),  //
        0, fy / z, -fy * y / (z * z);
    const Eigen::Matrix<double, 2, 3> A = J * Wr * M;
    const Eigen::Matrix2d Mc = A * A.transpose();
    const double a = Mc(0, 0) + eps2d, b = 0.5 * (Mc(0, 1) + Mc(1, 0)), c = Mc(1, 1) + eps2d;
    // det(A A^T + eps I) = det(A A^T) + eps tr(A A^T) + eps^2, and det(A A^T) is the sum
    // of the squared 2x2 minors of A (Cauchy-Binet): never negative, no cancellation of
    // two huge products for long thin Gaussians.
    double detM = 0;
    for (int u = 0; u < 3; ++u)
      for (int v = u + 1; v < 3; ++v) {
        const double minor = A(0, u) * A(1, v) - A(0, v) * A(1, u);
        detM += minor * minor;
      }
    const double det = detM + eps2d * (Mc(0, 0) + Mc(1, 1)) + eps2d * eps2d;
    if (!(det > 0) || !std::isfinite(det) || !std::isfinite(a) || !std::isfinite(b) || !std::isfinite(c))
      continue;  // degenerate (eps2d = 0) or overflowed: nothing sensible to draw

    Projected P;
    P.index = static_cast<int>(i);
    P.z = z;
    P.mu_x = fx * x / z + cx;
    P.mu_y = fy * y / z + cy;
    P.ca = c / det;
    P.cb = -b / det;
    P.cc = a / det;
    P.opacity = o;

    // Rule 4.
    if (s.extent == ExtentRule::kOpacityAware) {
      const double l = std::max(std::log(255.0 * o), 0.0);  // >= 0 for o >= 1/255
      P.hx = std::sqrt(2.0 * l * a);
      P.hy = std::sqrt(2.0 * l * c);
    } else {
      const double mid = 0.5 * (a + c);
      const double lambda_max = mid + std::sqrt(std::max(mid * mid - det, 0.0));
      P.hx = P.hy = 3.0 * std::sqrt(lambda_max);
    }
    if (!(P.mu_x + P.hx >= 0 && P.mu_x - P.hx <= W && P.mu_y + P.hy >= 0 && P.mu_y - P.hy <= H))
      continue;  // the rectangle misses the image [0, W] x [0, H]

    // Rule 5, along the world-frame direction from the camera centre.
    Eigen::Vector3d d = m - centre;
    const double len = d.norm();
    if (len > 0) d /= len;
    double basis[16];
    shBasis<double>(s.sh_degree, d.x(), d.y(), d.z(), basis);
    for (int ch = 0; ch < 3; ++ch) {
      double v = 0.5;
      for (int k = 0; k < shCoeffCount(s.sh_degree); ++k) v += g.sh[(i * K + k) * 3 + ch] * basis[k];
      P.color[ch] = std::max(v, 0.0);
    }

    out.visible[i] = 1;
    out.radii[i] = std::max(P.hx, P.hy);
    kept.push_back(P);
  }

  // Rule 6: one global order by (camera z, index); per pixel it is the same order.
  std::sort(kept.begin(), kept.end(), [](const Projected& p, const Projected& q) {
    if (p.z != q.z) return p.z < q.z;
    return p.index < q.index;
  });

  // Rule 7, pixel by pixel.
  const double bg[3] = {s.background[0], s.background[1], s.background[2]};
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i) {
      const double u = i + 0.5, v = j + 0.5;
      double T = 1.0, C[3] = {0, 0, 0}, D = 0;
      int count = 0;
      for (const Projected& P : kept) {
        const double dx = u - P.mu_x, dy = v - P.mu_y;
        if (!(std::abs(dx) <= P.hx && std::abs(dy) <= P.hy)) continue;
        const double power = -0.5 * (P.ca * dx * dx + 2.0 * P.cb * dx * dy + P.cc * dy * dy);
        const double alpha = std::min(kMaxAlphaD, P.opacity * std::exp(power));
        if (!(alpha >= kMinAlphaD)) continue;
        if (T * (1.0 - alpha) < kMinTransmittanceD) break;
        for (int ch = 0; ch < 3; ++ch) C[ch] += T * alpha * P.color[ch];
        D += T * alpha * P.z;
        T *= 1.0 - alpha;
        ++count;
      }
      const std::size_t pix = static_cast<std::size_t>(j) * W + i;
      for (int ch = 0; ch < 3; ++ch) out.rgb[3 * pix + ch] = C[ch] + T * bg[ch];
      out.alpha[pix] = 1.0 - T;
      out.depth[pix] = (1.0 - T < kMinCoverage) ? 0.0 : D / (1.0 - T);
      out.contributors[pix] = count;
    }
  return out;
}

}  // namespace saresgs
