#include "splat/splat_file.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <bit>
#include <stdexcept>

namespace saresgs {

namespace {

std::uint8_t unitToByte(double v) { return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); }

}  // namespace

std::string splatFileBytes(const Gaussians& g) {
  const std::size_t n = g.size();
  const std::size_t k = static_cast<std::size_t>(g.shCoeffs());
  if (g.means.size() != 3 * n || g.log_scales.size() != 3 * n || g.rotations.size() != 4 * n ||
      g.sh.size() != k * 3 * n)
    throw std::invalid_argument("splatFileBytes: the model's arrays are inconsistent");
  std::string out(n * kSplatRecordBytes, '\0');
  for (std::size_t i = 0; i < n; ++i) {
    char* rec = out.data() + i * kSplatRecordBytes;
    float f[6];
    for (int c = 0; c < 3; ++c) {
      f[c] = g.means[3 * i + c];
      f[3 + c] = static_cast<float>(std::exp(static_cast<double>(g.log_scales[3 * i + c])));
    }
    std::memcpy(rec, f, sizeof f);  // little-endian hosts only (static_assert below)
    auto* b = reinterpret_cast<std::uint8_t*>(rec + 24);
    for (int c = 0; c < 3; ++c) b[c] = unitToByte(0.5 + kShC0 * g.sh[(i * k) * 3 + c]);
    b[3] = unitToByte(1.0 / (1.0 + std::exp(-static_cast<double>(g.opacities[i]))));
    const float* q = &g.rotations[4 * i];
    double norm = 0;
    for (int c = 0; c < 4; ++c) norm += static_cast<double>(q[c]) * q[c];
    norm = std::sqrt(norm);
    auto* r = reinterpret_cast<std::uint8_t*>(rec + 28);
    for (int c = 0; c < 4; ++c) {
      // a zero quaternion is the identity (gaussians.h)
      const double u = norm > 1e-12 ? q[c] / norm : (c == 0 ? 1.0 : 0.0);
      r[c] = static_cast<std::uint8_t>(std::clamp<long>(std::lround(128.0 + 128.0 * u), 0, 255));
    }
  }
  return out;
}

static_assert(std::endian::native == std::endian::little, "the .splat writer copies floats as they lie in memory");

}  // namespace saresgs
