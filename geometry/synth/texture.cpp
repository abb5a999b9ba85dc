#include "geometry/synth/texture.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "geometry/error.h"
#include "geometry/synth/noise.h"

namespace saresgs::synth {

Color rgb(int r, int g, int b) { return Color(r, g, b) / 255.0f; }

namespace {

using Eigen::Vector3f;

// Lattice-based textures are shifted by this fraction of a cell so that axis-aligned
// faces at round coordinates (walls at x = 4, the floor at z = 0) do not fall exactly
// on a cell boundary, where rounding would flip between neighbouring cells.
constexpr float kShift = 0.3183f;

inline float fract(float x) { return x - std::floor(x); }
inline Color mix(const Color& a, const Color& b, float t) { return a + (b - a) * t; }
inline float smoothstep(float e0, float e1, float x) {
  const float t = std::clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
  return t * t * (3 - 2 * t);
}
inline std::int64_t floorInt(float x) { return static_cast<std::int64_t>(std::floor(x)); }
inline Color clamp01(const Color& c) { return c.cwiseMax(0.0f).cwiseMin(1.0f); }

// The two in-plane coordinates for a projection along the dominant normal axis; the
// second one is z (vertical) whenever the plane contains z.
inline int dominantAxis(const Vector3f& n) {
  const Vector3f a = n.cwiseAbs();
  return a.x() >= a.y() && a.x() >= a.z() ? 0 : (a.y() >= a.z() ? 1 : 2);
}
inline Eigen::Vector2f planeCoords(const Vector3f& p, int axis) {
  switch (axis) {
    case 0:
      return {p.y(), p.z()};
    case 1:
      return {p.x(), p.z()};
    default:
      return {p.x(), p.y()};
  }
}

class Checker final : public Texture {
 public:
  Checker(float cell, Color a, Color b, std::uint64_t seed) : cell_(cell), a_(a), b_(b), seed_(seed) {}
  Color albedo(const Vector3f& p, const Vector3f&) const override {
    const Vector3f q = p / cell_ + Vector3f::Constant(kShift);
    const auto parity = (floorInt(q.x()) + floorInt(q.y()) + floorInt(q.z())) & 1;
    const float m = 0.9f + 0.1f * fbm(p * 6.0f, 3, seed_);
    return clamp01((parity ? a_ : b_) * m);
  }
  std::string describe() const override { return "procedural:checker"; }

 private:
  float cell_;
  Color a_, b_;
  std::uint64_t seed_;
};

class Stripes final : public Texture {
 public:
  Stripes(const Vector3f& axis, float period, Color a, Color b, Color c, std::uint64_t seed)
      : axis_(axis.normalized()), period_(period), c_{a, b, c}, seed_(seed) {}
  Color albedo(const Vector3f& p, const Vector3f&) const override {
    const float t = p.dot(axis_) / period_ + kShift + 0.12f * fbm(p * 1.5f, 3, seed_);
    const auto k = floorInt(t);
    const int band = static_cast<int>(((k % 3) + 3) % 3);
    // A thin darker line at each band edge, and a faint fabric-like grain.
    const float f = fract(t);
    const float edge = 1.0f - 0.25f * (1.0f - smoothstep(0.0f, 0.04f, std::min(f, 1 - f)));
    const float grain = 0.92f + 0.08f * fbm(p * 12.0f, 2, seed_ + 7);
    return clamp01(c_[band] * edge * grain);
  }
  std::string describe() const override { return "procedural:stripes"; }

 private:
  Vector3f axis_;
  float period_;
  Color c_[3];
  std::uint64_t seed_;
};

class Marble final : public Texture {
 public:
  Marble(float scale, Color base, Color vein, std::uint64_t seed)
      : scale_(scale), base_(base), vein_(vein), seed_(seed) {}
  Color albedo(const Vector3f& p, const Vector3f&) const override {
    const Vector3f dir(0.6f, 0.3f, 0.74f);
    const float s = std::sin(scale_ * p.dot(dir) * 5.0f + 4.0f * turbulence(p * scale_, 5, seed_));
    const float t = std::pow(0.5f + 0.5f * s, 0.25f);  // narrow dark veins
    const float cloud = 0.93f + 0.07f * fbm(p * (3.0f * scale_), 3, seed_ + 3);
    return clamp01(mix(vein_, base_, t) * cloud);
  }
  std::string describe() const override { return "procedural:marble"; }

 private:
  float scale_;
  Color base_, vein_;
  std::uint64_t seed_;
};

class Wood final : public Texture {
 public:
  Wood(const Vector3f& axis, const Vector3f& centre, float spacing, Color light, Color dark, std::uint64_t seed)
      : axis_(axis.normalized()), centre_(centre), spacing_(spacing), light_(light), dark_(dark), seed_(seed) {}
  Color albedo(const Vector3f& p, const Vector3f&) const override {
    const Vector3f q = p - centre_;
    const Vector3f radial = q - q.dot(axis_) * axis_;
    const float r = radial.norm() / spacing_ + 0.6f * fbm(p * 1.2f, 3, seed_);
    const float ring = fract(r);
    const float dark = smoothstep(0.55f, 0.95f, ring) * (1.0f - smoothstep(0.95f, 1.0f, ring));
    // Fine grain: noise stretched along the axis.
    const Vector3f g = radial * 40.0f + axis_ * (q.dot(axis_) * 2.0f);
    const float grain = 0.9f + 0.1f * fbm(g, 2, seed_ + 11);
    return clamp01(mix(light_, dark_, 0.75f * dark) * grain);
  }
  std::string describe() const override { return "procedural:wood"; }

 private:
  Vector3f axis_, centre_;
  float spacing_;
  Color light_, dark_;
  std::uint64_t seed_;
};

class Planks final : public Texture {
 public:
  Planks(float width, float length, Color light, Color dark, std::uint64_t seed)
      : width_(width), length_(length), light_(light), dark_(dark), seed_(seed) {}
  Color albedo(const Vector3f& p3, const Vector3f& n) const override {
    const int axis = dominantAxis(n);
    const Eigen::Vector2f uv = planeCoords(p3, axis);
    const Vector3f p(uv.x(), uv.y(), static_cast<float>(axis) * 10.0f);
    const float v = p.y() / width_ + kShift;
    const auto row = floorInt(v);
    const float fv = fract(v);
    const float u = p.x() / length_ + unitFloat(hashInts(row, axis, 1, seed_)) + kShift;
    const auto col = floorInt(u);
    const float fu = fract(u);
    const std::uint64_t h = hashInts(row, col, 2, seed_);
    // Grain lines along the plank: rings of a log whose axis lies along x.
    const float cy = (fv - 0.5f) * width_ + (unitFloat(h) - 0.5f) * 0.6f;
    const float cz = 0.15f + 0.3f * unitFloat(mix64(h));
    const Vector3f q(p.x() * 0.4f, cy * 6.0f, static_cast<float>(col) * 3.1f);
    const float r = std::hypot(cy, cz) * 28.0f + 1.5f * fbm(q, 3, seed_ + 5);
    const float ring = smoothstep(0.5f, 0.9f, fract(r));
    const float tint = 0.8f + 0.35f * unitFloat(mix64(h + 17));
    Color c = mix(light_, dark_, 0.6f * ring) * tint;
    // Dark seams between planks.
    const float seam_v = std::min(fv, 1 - fv) * width_;
    const float seam_u = std::min(fu, 1 - fu) * length_;
    const float seam = smoothstep(0.004f, 0.012f, std::min(seam_u, seam_v));
    c *= 0.35f + 0.65f * seam;
    return clamp01(c);
  }
  std::string describe() const override { return "procedural:planks"; }

 private:
  float width_, length_;
  Color light_, dark_;
  std::uint64_t seed_;
};

class Bricks final : public Texture {
 public:
  Bricks(float w, float h, float mortar, Color brick, Color joint, std::uint64_t seed)
      : w_(w), h_(h), mortar_(mortar), brick_(brick), joint_(joint), seed_(seed) {}
  Color albedo(const Vector3f& p, const Vector3f& n) const override {
    const int axis = dominantAxis(n);
    const Eigen::Vector2f uv = planeCoords(p, axis);
    const float v = uv.y() / h_ + kShift;
    const auto row = floorInt(v);
    const float u = uv.x() / w_ + kShift + ((row & 1) ? 0.5f : 0.0f);
    const auto col = floorInt(u);
    const float du = std::min(fract(u), 1 - fract(u)) * w_;
    const float dv = std::min(fract(v), 1 - fract(v)) * h_;
    const float rough = fbm(p * 9.0f, 3, seed_ + 1);
    if (std::min(du, dv) < 0.5f * mortar_ * (1.0f + 0.3f * rough)) return clamp01(joint_ * (0.9f + 0.1f * rough));
    const std::uint64_t hsh = hashInts(row, col, axis, seed_);
    const float shade = 0.75f + 0.45f * unitFloat(hsh);
    const Color hue(1.0f + 0.12f * (unitFloat(mix64(hsh)) - 0.5f), 1.0f,
                    1.0f + 0.12f * (unitFloat(mix64(hsh + 1)) - 0.5f));
    return clamp01(brick_.cwiseProduct(hue) * shade * (0.88f + 0.12f * rough));
  }
  std::string describe() const override { return "procedural:bricks"; }

 private:
  float w_, h_, mortar_;
  Color brick_, joint_;
  std::uint64_t seed_;
};

class Tiles final : public Texture {
 public:
  Tiles(float size, float grout, Color a, Color b, Color joint, std::uint64_t seed)
      : size_(size), grout_(grout), a_(a), b_(b), joint_(joint), seed_(seed) {}
  Color albedo(const Vector3f& p, const Vector3f& n) const override {
    const int axis = dominantAxis(n);
    const Eigen::Vector2f uv = planeCoords(p, axis) / size_ + Eigen::Vector2f::Constant(kShift);
    const auto i = floorInt(uv.x()), j = floorInt(uv.y());
    const float du = std::min(fract(uv.x()), 1 - fract(uv.x())) * size_;
    const float dv = std::min(fract(uv.y()), 1 - fract(uv.y())) * size_;
    if (std::min(du, dv) < 0.5f * grout_) return joint_;
    const std::uint64_t h = hashInts(i, j, axis, seed_);
    const Color base = ((i + j) & 1) ? a_ : b_;
    const float m = 0.85f + 0.15f * fbm(p * 5.0f, 4, seed_ + static_cast<std::uint64_t>(h % 97));
    return clamp01(base * m * (0.92f + 0.16f * unitFloat(h)));
  }
  std::string describe() const override { return "procedural:tiles"; }

 private:
  float size_, grout_;
  Color a_, b_, joint_;
  std::uint64_t seed_;
};

class Speckle final : public Texture {
 public:
  Speckle(float scale, Color base, Color spot, std::uint64_t seed)
      : scale_(scale), base_(base), spot_(spot), seed_(seed) {}
  Color albedo(const Vector3f& p, const Vector3f&) const override {
    const float low = fbm(p * scale_, 4, seed_);
    const float high = gradientNoise(p * (scale_ * 12.0f), seed_ + 9);
    const float spots = smoothstep(0.25f, 0.45f, high);
    return clamp01(mix(base_ * (0.88f + 0.12f * low), spot_, 0.8f * spots));
  }
  std::string describe() const override { return "procedural:speckle"; }

 private:
  float scale_;
  Color base_, spot_;
  std::uint64_t seed_;
};

class Dots final : public Texture {
 public:
  Dots(float spacing, float radius, Color background, Color dot, std::uint64_t seed)
      : spacing_(spacing), radius_(radius), bg_(background), dot_(dot), seed_(seed) {}
  Color albedo(const Vector3f& p, const Vector3f&) const override {
    // One dot centre at a random place in each lattice cell (Worley-style), so that
    // every plane, whatever its position, cuts through some of the dots.
    const Vector3f q = p / spacing_;
    const std::int64_t cx = floorInt(q.x()), cy = floorInt(q.y()), cz = floorInt(q.z());
    float best = std::numeric_limits<float>::infinity();
    std::uint64_t best_hash = 0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const std::uint64_t h = hashInts(cx + dx, cy + dy, cz + dz, seed_);
          const Vector3f f(static_cast<float>(cx + dx) + 0.15f + 0.7f * unitFloat(h),
                           static_cast<float>(cy + dy) + 0.15f + 0.7f * unitFloat(mix64(h)),
                           static_cast<float>(cz + dz) + 0.15f + 0.7f * unitFloat(mix64(h + 1)));
          const float d = (q - f).squaredNorm();
          if (d < best) {
            best = d;
            best_hash = h;
          }
        }
    const float m = 0.9f + 0.1f * fbm(p * 4.0f, 3, seed_);
    if (std::sqrt(best) * spacing_ < radius_)
      return clamp01(dot_ * (0.8f + 0.4f * unitFloat(mix64(best_hash + 2))) * m);
    return clamp01(bg_ * m);
  }
  std::string describe() const override { return "procedural:dots"; }

 private:
  float spacing_, radius_;
  Color bg_, dot_;
  std::uint64_t seed_;
};

class ImageTexture final : public Texture {
 public:
  ImageTexture(std::shared_ptr<const ImageF> img, Projection proj, float scale, std::string source)
      : img_(std::move(img)), proj_(proj), scale_(scale), source_(std::move(source)) {}
  Color albedo(const Vector3f& p, const Vector3f& n) const override {
    const ImageF& im = *img_;
    if (proj_ == Projection::Spherical) {
      const float len = p.norm();
      const Vector3f d = len > 0 ? Vector3f(p / len) : Vector3f::UnitZ();
      const float lon = std::atan2(d.y(), d.x());
      const float lat = std::acos(std::clamp(d.z(), -1.0f, 1.0f));
      return sampleBilinear(im, (lon / (2 * std::numbers::pi_v<float>)+0.5f) * im.width,
                            lat / std::numbers::pi_v<float> * im.height, false);
    }
    // Triplanar: blend the three axis projections with weights |n|^4.
    Vector3f w = n.cwiseAbs().array().pow(4.0f).matrix();
    w /= std::max(w.sum(), 1e-12f);
    Color c = Color::Zero();
    for (int axis = 0; axis < 3; ++axis) {
      if (w[axis] < 1e-3f) continue;
      const Eigen::Vector2f uv = planeCoords(p, axis) / scale_;
      // Image x along the first coordinate, image y downwards along the second.
      c += w[axis] * sampleBilinear(im, uv.x() * im.width, -uv.y() * im.width, true);
    }
    return clamp01(c);
  }
  std::string describe() const override { return source_; }

 private:
  std::shared_ptr<const ImageF> img_;
  Projection proj_;
  float scale_;
  std::string source_;
};

}  // namespace

Color sampleBilinear(const ImageF& img, float x, float y, bool wrap_y) {
  const int W = img.width, H = img.height;
  const float fx = x - 0.5f, fy = y - 0.5f;
  const float x0f = std::floor(fx), y0f = std::floor(fy);
  const float tx = fx - x0f, ty = fy - y0f;
  auto wrap = [](std::int64_t i, int n) { return static_cast<int>(((i % n) + n) % n); };
  const auto x0 = static_cast<std::int64_t>(x0f), y0 = static_cast<std::int64_t>(y0f);
  const int xa = wrap(x0, W), xb = wrap(x0 + 1, W);
  int ya, yb;
  if (wrap_y) {
    ya = wrap(y0, H);
    yb = wrap(y0 + 1, H);
  } else {
    ya = static_cast<int>(std::clamp<std::int64_t>(y0, 0, H - 1));
    yb = static_cast<int>(std::clamp<std::int64_t>(y0 + 1, 0, H - 1));
  }
  auto px = [&](int xx, int yy) {
    const int c = img.channels;
    if (c >= 3) return Color(img.at(xx, yy, 0), img.at(xx, yy, 1), img.at(xx, yy, 2));
    return Color::Constant(img.at(xx, yy, 0)).eval();
  };
  const Color top = px(xa, ya) * (1 - tx) + px(xb, ya) * tx;
  const Color bottom = px(xa, yb) * (1 - tx) + px(xb, yb) * tx;
  return top * (1 - ty) + bottom * ty;
}

Projection parseProjection(const std::string& name) {
  if (name == "triplanar") return Projection::Triplanar;
  if (name == "spherical") return Projection::Spherical;
  throw InputError("options", "projection", "expected triplanar or spherical, got '" + name + "'");
}

std::shared_ptr<Texture> makeChecker(float cell, Color a, Color b, std::uint64_t seed) {
  return std::make_shared<Checker>(cell, a, b, seed);
}
std::shared_ptr<Texture> makeStripes(const Eigen::Vector3f& axis, float period, Color a, Color b, Color c,
                                     std::uint64_t seed) {
  return std::make_shared<Stripes>(axis, period, a, b, c, seed);
}
std::shared_ptr<Texture> makeMarble(float scale, Color base, Color vein, std::uint64_t seed) {
  return std::make_shared<Marble>(scale, base, vein, seed);
}
std::shared_ptr<Texture> makeWood(const Eigen::Vector3f& axis, const Eigen::Vector3f& centre, float ring_spacing,
                                  Color light, Color dark, std::uint64_t seed) {
  return std::make_shared<Wood>(axis, centre, ring_spacing, light, dark, seed);
}
std::shared_ptr<Texture> makePlanks(float width, float length, Color light, Color dark, std::uint64_t seed) {
  return std::make_shared<Planks>(width, length, light, dark, seed);
}
std::shared_ptr<Texture> makeBricks(float w, float h, float mortar, Color brick, Color joint, std::uint64_t seed) {
  return std::make_shared<Bricks>(w, h, mortar, brick, joint, seed);
}
std::shared_ptr<Texture> makeTiles(float size, float grout, Color a, Color b, Color joint, std::uint64_t seed) {
  return std::make_shared<Tiles>(size, grout, a, b, joint, seed);
}
std::shared_ptr<Texture> makeSpeckle(float scale, Color base, Color spot, std::uint64_t seed) {
  return std::make_shared<Speckle>(scale, base, spot, seed);
}
std::shared_ptr<Texture> makeDots(float spacing, float radius, Color background, Color dot, std::uint64_t seed) {
  return std::make_shared<Dots>(spacing, radius, background, dot, seed);
}
std::shared_ptr<Texture> makeImageTexture(std::shared_ptr<const ImageF> image, Projection projection, float scale,
                                          const std::string& source) {
  return std::make_shared<ImageTexture>(std::move(image), projection, scale, source);
}

}  // namespace saresgs::synth
