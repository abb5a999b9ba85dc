#include "geometry/synth/noise.h"

#include <cmath>

namespace saresgs::synth {

std::uint64_t mix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

std::uint64_t hashInts(std::int64_t a, std::int64_t b, std::int64_t c, std::uint64_t seed) {
  std::uint64_t h = mix64(seed ^ 0x5851F42D4C957F2Dull);
  h = mix64(h ^ static_cast<std::uint64_t>(a));
  h = mix64(h ^ static_cast<std::uint64_t>(b));
  h = mix64(h ^ static_cast<std::uint64_t>(c));
  return h;
}

float unitFloat(std::uint64_t h) { return static_cast<float>(h >> 40) * (1.0f / 16777216.0f); }

namespace {

inline float fade(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }

// One of the 12 cube-edge directions, picked by the lattice hash, dotted with the offset:
// hash 0-3 gives +-x +-y, 4-7 +-x +-z, 8-11 +-y +-z (bit 0 flips the first, bit 1 the second).
inline float grad(std::uint64_t h, float x, float y, float z) {
  const std::uint64_t k = h % 12;
  const float u = k < 8 ? x : y, v = k < 4 ? y : z;
  return ((k & 1) ? -u : u) + ((k & 2) ? -v : v);
}

}  // namespace

float gradientNoise(const Eigen::Vector3f& p, std::uint64_t seed) {
  const float fx = std::floor(p.x()), fy = std::floor(p.y()), fz = std::floor(p.z());
  const auto ix = static_cast<std::int64_t>(fx), iy = static_cast<std::int64_t>(fy), iz = static_cast<std::int64_t>(fz);
  const float x = p.x() - fx, y = p.y() - fy, z = p.z() - fz;
  float c[8];
  for (int k = 0; k < 8; ++k) {
    const int dx = k & 1, dy = (k >> 1) & 1, dz = (k >> 2) & 1;
    c[k] = grad(hashInts(ix + dx, iy + dy, iz + dz, seed), x - dx, y - dy, z - dz);
  }
  const float u = fade(x), v = fade(y), w = fade(z);
  auto lerp = [](float a, float b, float t) { return a + t * (b - a); };
  const float x00 = lerp(c[0], c[1], u), x10 = lerp(c[2], c[3], u);
  const float x01 = lerp(c[4], c[5], u), x11 = lerp(c[6], c[7], u);
  return lerp(lerp(x00, x10, v), lerp(x01, x11, v), w);
}

float fbm(const Eigen::Vector3f& p, int octaves, std::uint64_t seed) {
  float sum = 0, amp = 1, norm = 0;
  Eigen::Vector3f q = p;
  for (int o = 0; o < octaves; ++o) {
    sum += amp * gradientNoise(q, seed + 131 * o);
    norm += amp;
    amp *= 0.5f;
    // A fixed offset per octave hides the lattice alignment of successive layers.
    q = q * 2.0f + Eigen::Vector3f(17.31f, -9.73f, 5.17f);
  }
  return sum / norm;
}

float turbulence(const Eigen::Vector3f& p, int octaves, std::uint64_t seed) {
  float sum = 0, amp = 1, norm = 0;
  Eigen::Vector3f q = p;
  for (int o = 0; o < octaves; ++o) {
    sum += amp * std::abs(gradientNoise(q, seed + 131 * o));
    norm += amp;
    amp *= 0.5f;
    q = q * 2.0f + Eigen::Vector3f(17.31f, -9.73f, 5.17f);
  }
  return sum / norm;
}

}  // namespace saresgs::synth
