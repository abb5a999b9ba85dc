#include "geometry/lifting/epipolar_refine.h"
#include "geometry/float_env.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/LU>
#include <array>
#include <cmath>
#include <optional>

namespace saresgs {

namespace {

// Luma of an RGB (or grey) image, for patch scores.
struct Luma {
  int width = 0, height = 0;
  std::vector<float> v;

  explicit Luma(const ImageF& img)
      : width(img.width), height(img.height), v(img.data.size() / std::max(img.channels, 1)) {
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const float l = img.channels >= 3
                            ? 0.299f * img.at(x, y, 0) + 0.587f * img.at(x, y, 1) + 0.114f * img.at(x, y, 2)
                            : img.at(x, y, 0);
        v[static_cast<std::size_t>(y) * width + x] = std::isfinite(l) ? l : 0.0f;
      }
  }
  // Bilinear value at camera-convention coordinates (pixel centres at +0.5); nothing
  // outside the hull of the pixel centres.
  std::optional<double> sample(double x, double y) const {
    const double u = x - 0.5, w = y - 0.5;
    if (!(u >= 0 && w >= 0 && u <= width - 1 && w <= height - 1)) return std::nullopt;
    const int i = std::min(static_cast<int>(u), width - 2), j = std::min(static_cast<int>(w), height - 2);
    const double ax = u - i, ay = w - j;
    const float* r0 = &v[static_cast<std::size_t>(j) * width + i];
    const float* r1 = r0 + width;
    return (1 - ay) * ((1 - ax) * r0[0] + ax * r0[1]) + ay * ((1 - ax) * r1[0] + ax * r1[1]);
  }
};

struct EpipolarMap {
  Eigen::Matrix3d M;   // K1 A K0^-1: maps a homogeneous pixel of image 0 at unit depth
  Eigen::Vector3d hb;  // K1 b: the image-1 direction that inverse depth rho scales
};

// In camera-1 coordinates a point at depth z on the ray of pixel x0 is
//   X1 = z A K0^-1 x0 + b,  A = R1 R0^T,  b = t1 - A t0,
// so X1 / z = M x0 + rho hb with rho = 1/z: a homogeneous image point linear in rho.
EpipolarMap pairGeometry(const Camera& c0, const Camera& c1) {
  const Eigen::Matrix3d A = c1.R * c0.R.transpose();
  EpipolarMap g;
  g.M = c1.K.matrix() * A * c0.K.matrix().inverse();
  g.hb = c1.K.matrix() * (c1.t - A * c0.t);
  return g;
}

std::optional<Eigen::Vector2d> dehom(const Eigen::Vector3d& h) {
  if (!(h.z() > 1e-12)) return std::nullopt;
  const Eigen::Vector2d p = h.head<2>() / h.z();
  if (!p.allFinite()) return std::nullopt;
  return p;
}

std::optional<Correspondence> refineOne(const EpipolarMap& g, const Luma& l0, const Luma& l1, const Correspondence& m,
                                        const EpipolarRefineOptions& o) {
  if (!m.x0.allFinite() || !m.x1.allFinite()) return std::nullopt;
  const Eigen::Vector3d h0 = g.M * Eigen::Vector3d(m.x0.x(), m.x0.y(), 1.0);
  // The line: x(rho) = (a + rho c) / (w + rho gz); rho = 0 is the vanishing point of the
  // ray (its image at infinite depth).
  const Eigen::Vector2d a = h0.head<2>(), c = g.hb.head<2>();
  const double w = h0.z(), gz = g.hb.z();
  const auto v = dehom(h0);
  if (!v) return std::nullopt;
  const Eigen::Vector2d dir = c * w - a * gz;  // (w^2 times) dx/drho at rho = 0
  const double dn = dir.norm();
  if (!(dn > 1e-12 * (c.norm() * std::abs(w) + a.norm() * std::abs(gz)))) return std::nullopt;
  const Eigen::Vector2d u = dir / dn;
  const Eigen::Vector2d rel = m.x1 - *v;
  if (!(std::abs(rel.x() * u.y() - rel.y() * u.x()) < o.max_epipolar_px)) return std::nullopt;
  // rho of the foot of the perpendicular, from the better-conditioned coordinate.
  const Eigen::Vector2d p = *v + rel.dot(u) * u;
  const int k = std::abs(u.x()) >= std::abs(u.y()) ? 0 : 1;
  const double rho0 = (p[k] * w - a[k]) / (c[k] - p[k] * gz);
  if (!(rho0 > 0) || !std::isfinite(rho0)) return std::nullopt;
  const double speed = dn / ((w + rho0 * gz) * (w + rho0 * gz));  // pixels per unit rho
  if (!(speed > 0) || !std::isfinite(speed)) return std::nullopt;
  const double drho = o.step_px / speed;
  const int steps = std::max(1, static_cast<int>(std::lround(o.search_px / o.step_px)));

  // Reference patch around x0 and the homogeneous image-1 point of each of its pixels at
  // unit depth; a hypothesis rho adds rho * hb to all of them.
  const int r = std::max(0, o.patch_radius);
  const int n = (2 * r + 1) * (2 * r + 1);
  std::vector<double> ref(n);
  std::vector<Eigen::Vector3d> base(n);
  double mean0 = 0;
  for (int dy = -r, i = 0; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx, ++i) {
      const auto s = l0.sample(m.x0.x() + dx, m.x0.y() + dy);
      if (!s) return std::nullopt;
      ref[i] = *s;
      mean0 += *s;
      base[i] = h0 + g.M.col(0) * dx + g.M.col(1) * dy;
    }
  mean0 /= n;
  double var0 = 0;
  for (double& x : ref) {
    x -= mean0;
    var0 += x * x;
  }
  if (!(std::sqrt(var0 / n) >= o.min_patch_std)) return std::nullopt;

  constexpr double kInvalid = -2.0;  // below any correlation
  std::vector<double> score(2 * steps + 1, kInvalid);
  std::vector<double> cur(n);
  for (int s = -steps; s <= steps; ++s) {
    const double rho = rho0 + s * drho;
    if (!(rho > 0)) continue;
    double mean1 = 0;
    bool inside = true;
    for (int i = 0; i < n && inside; ++i) {
      const auto q = dehom(base[i] + rho * g.hb);
      const auto val = q ? l1.sample(q->x(), q->y()) : std::nullopt;
      if (!val)
        inside = false;
      else {
        cur[i] = *val;
        mean1 += *val;
      }
    }
    if (!inside) continue;
    mean1 /= n;
    double cov = 0, var1 = 0;
    for (int i = 0; i < n; ++i) {
      const double d = cur[i] - mean1;
      cov += ref[i] * d;
      var1 += d * d;
    }
    if (var1 > 0) score[s + steps] = cov / std::sqrt(var0 * var1);
  }
  int best = -1;
  for (int i = 0; i < static_cast<int>(score.size()); ++i)
    if (score[i] > kInvalid && (best < 0 || score[i] > score[best])) best = i;
  // At the end of the range the maximum is not bracketed: the flow was too far off.
  if (best <= 0 || best >= static_cast<int>(score.size()) - 1) return std::nullopt;
  const double sm = score[best - 1], s0 = score[best], sp = score[best + 1];
  if (sm <= kInvalid || sp <= kInvalid || !(s0 >= o.min_zncc)) return std::nullopt;
  const double curv = sm - 2 * s0 + sp;
  const double offset = curv < 0 ? std::clamp(0.5 * (sm - sp) / curv, -0.5, 0.5) : 0.0;
  const double rho = rho0 + (best - steps + offset) * drho;
  const auto x1 = dehom(h0 + rho * g.hb);
  if (!x1) return std::nullopt;
  // Move along the line only: the flow's distance from the line stays, so that the
  // reprojection test downstream still sees how epipolar-consistent the flow was.
  const Eigen::Vector2d across = rel - rel.dot(u) * u;
  return Correspondence{m.x0, *x1 + across};
}

}  // namespace

std::vector<Correspondence> refineOnEpipolarLines(const Camera& cam0, const ImageF& image0, const Camera& cam1,
                                                  const ImageF& image1, std::span<const Correspondence> matches,
                                                  const EpipolarRefineOptions& opts) {
  if (image0.empty() || image1.empty() || image0.width < 2 || image0.height < 2 || image1.width < 2 ||
      image1.height < 2)
    return {};
  const EpipolarMap g = pairGeometry(cam0, cam1);
  if (!g.M.allFinite() || !g.hb.allFinite()) return {};
  const Luma l0(image0), l1(image1);
  std::vector<std::optional<Correspondence>> slot(matches.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, matches.size(), 64),
                    [&](const tbb::blocked_range<std::size_t>& rg) {
                      const FloatEnvGuard fenv;  // geometry/float_env.h
                      for (std::size_t i = rg.begin(); i != rg.end(); ++i)
                        slot[i] = refineOne(g, l0, l1, matches[i], opts);
                    });
  std::vector<Correspondence> out;
  for (const auto& s : slot)
    if (s) out.push_back(*s);
  return out;
}

}  // namespace saresgs
