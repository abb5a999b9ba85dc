// How far the forward tile kernel is from its own arithmetic (docs/DECISIONS.md,
// "0.6x on a step"). A developer's experiment, not part of the build or the tests:
//
//   g++ -std=c++20 -O3 -mavx2 -mfma -ffp-contract=off -DNDEBUG -I. \
//       docs/experiments/forward_floor.cpp -o /tmp/forward_floor && /tmp/forward_floor
//
// It compiles splat/raster/raster_kernels_impl.h with the AVX2 options (Avx2Isa) and times, in ns per evaluated pixel lane:
//   reg2  - compositeFloor: the kernel's per-lane arithmetic on two blocks held in registers
//           (the lattice's arithmetic, G by products; the exponent and exp2 per block
//           that the numbers in docs/DECISIONS.md were measured with are evalLanes,
//           still used off the lattice);
//   mem17 - the same arithmetic with each block's state loaded and stored every step, over
//           17 blocks of a tile (what a block-major loop order would save is mem17 - reg2);
//   tile  - compositeTile itself on one synthetic 16x16 tile of 600 Gaussians (sigma 1-2,
//           1.5-3 and 2-4 px, opacity 0.05 so that no pixel saturates), its loops, spans and
//           per-pair setup included.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "splat/raster/raster_kernels.h"

namespace saresgs::raster_kernels {
using KernelIsa = Avx2Isa;
}

#include "splat/raster/raster_kernels_impl.h"

namespace saresgs::raster_kernels {
// compositeFloor's loop (raster_kernels_impl.h), its constants and per-lane work, with the
// blocks' state in a tile's ForwardState instead of registers.
__attribute__((noinline)) float memoryFloor(long n, int blocks) {
  static ForwardState F;
  F.init(kTile, kTile);  // every pixel live: transmittance 1, sums 0
  const vf ha = vs(-0.5f * kLog2e * 0.02f), o = vs(0.6f), hx = vs(1e6f), qy = vs(-0.01f), by = vs(0.002f);
  const vi all = vi{} - 1;
  const vf colour[3] = {vs(0.3f), vs(0.5f), vs(0.7f)};
  const vf start = laneColCentres() - vs(2.0f);
  for (long i = 0; i < n; ++i) {
    const vf dx = start + vs(static_cast<float>(i & 1023) * (1.0f / 1024.0f));
    for (int k = 0; k < blocks; ++k) {
      ForwardBlock& B = F.b[k];
      const Lanes lanes = evalLanes(dx + vs(static_cast<float>(4 * (k & 1))), ha, qy, by, o, hx, all);
      ForwardState::step<false>(B, lanes, colour[0], colour[1], colour[2], vs(2.0f), vs(1.0f));
      B.Tr = vmax(B.Tr, vs(0.5f));
    }
  }
  vf sum = vs(0.0f);
  for (int k = 0; k < blocks; ++k) sum = sum + F.b[k].C0 + F.b[k].D + F.b[k].contrib;
  return hsum(sum);
}

long evaluatedLanes(const std::vector<TileGaussian<float>>& q) {
  long n = 0;
  for (const auto& g : q) forEachBlock(g, 0, 0, kTile, kTile, [&](int, const Lanes&, vf) { n += L; });
  return n;
}
}  // namespace saresgs::raster_kernels

using namespace saresgs::raster_kernels;
using Clock = std::chrono::steady_clock;

static double seconds(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

static void tile(float smin, float smax) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> U(0, 1);
  std::vector<saresgs::TileGaussian<float>> q(600);
  for (auto& g : q) {
    g.mx = 16 * U(rng);
    g.my = 16 * U(rng);
    const float s = smin + (smax - smin) * U(rng), h = 3 * s;
    g.a = g.c = 1 / (s * s);
    g.b = 0;
    g.o = 0.05f;
    g.hx = g.hy = h;
    g.depth = 1;
    g.col[0] = g.col[1] = g.col[2] = 0.5f;
    g.chord_slope = 0;
    g.chord_k0 = h * h;
    g.chord_k1 = 1;
    g.px0 = static_cast<int>(std::floor(g.mx - h));
    g.px1 = static_cast<int>(std::floor(g.mx + h));
    g.py0 = static_cast<int>(std::floor(g.my - h));
    g.py1 = static_cast<int>(std::floor(g.my + h));
  }
  std::vector<float> rgb(256 * 3), alpha(256), depth(256), T(256);
  std::vector<int> count(256);
  std::vector<std::uint32_t> walked(256);
  const saresgs::raster_kernels::ForwardOut out{16,           rgb.data(), alpha.data(), depth.data(),
                                                count.data(), T.data(),   walked.data()};
  const float bg[3] = {0, 0, 0};
  const long lanes = evaluatedLanes(q);
  const int reps = 2000;
  const auto t0 = Clock::now();
  for (int r = 0; r < reps; ++r) compositeTile(q.data(), static_cast<int>(q.size()), 0, 0, 16, 16, bg, out);
  const double t = seconds(t0);
  std::printf("tile sigma %.1f-%.1f px: %.3f ns per evaluated lane (%.1f blocks per pair)\n", smin, smax,
              t / (reps * static_cast<double>(lanes)) * 1e9, static_cast<double>(lanes) / L / q.size());
}

int main() {
  const long n = 2000000;
  for (int rep = 0; rep < 3; ++rep) {
    auto t0 = Clock::now();
    const float a = compositeFloor(n);
    const double reg = seconds(t0);
    t0 = Clock::now();
    const float b = memoryFloor(n / 8, 17);
    const double mem = seconds(t0);
    std::printf("reg2 %.3f ns/lane, mem17 %.3f ns/lane (checksums %g %g)\n", reg / (n * 2.0 * L) * 1e9,
                mem / (n / 8 * 17.0 * L) * 1e9, a, b);
    tile(1.0f, 2.0f);
    tile(1.5f, 3.0f);
    tile(2.0f, 4.0f);
  }
}
