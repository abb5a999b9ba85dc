#pragma once
// The tile walk's check (tests/splat/raster/test_raster_lattice*.cpp) on
// splat/raster/raster_kernels_impl.h compiled with the including test's KernelIsa (eight
// or four lanes, the baseline flags); everything here is that file's own.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "splat/raster/raster_kernels_impl.h"

namespace saresgs::raster_kernels {
namespace {

struct Spec {
  double mx, my, a, b, c, o;
};

// The kernels' view of a Gaussian (what tileData in raster_stages.h builds): the
// opacity-aware rectangle, its pixel span widened as there, and the alpha-ellipse chords
// when `chords` (else none: the rows cover the rectangle).
TileGaussian<float> tileGaussian(const Spec& s, bool chords) {
  const double det = s.a * s.c - s.b * s.b;
  const double k2 = 2.0 * std::log(255.0 * s.o);
  TileGaussian<float> q{};
  q.mx = static_cast<float>(s.mx);
  q.my = static_cast<float>(s.my);
  q.a = static_cast<float>(s.a);
  q.b = static_cast<float>(s.b);
  q.c = static_cast<float>(s.c);
  q.o = static_cast<float>(s.o);
  q.hx = static_cast<float>(std::sqrt(k2 * s.c / det));  // sqrt(k2 Sigma_xx)
  q.hy = static_cast<float>(std::sqrt(k2 * s.a / det));
  q.depth = 1.0f;
  auto span = [](double mean, double half, std::int32_t& lo, std::int32_t& hi) {
    const double h = half * (1.0 + 1e-6) + 1e-3;
    lo = static_cast<std::int32_t>(std::ceil(mean - h - 0.5));
    hi = static_cast<std::int32_t>(std::floor(mean + h - 0.5));
  };
  span(q.mx, q.hx, q.px0, q.px1);
  span(q.my, q.hy, q.py0, q.py1);
  q.chord_slope = 0.0f;
  q.chord_k0 = std::numeric_limits<float>::max();
  q.chord_k1 = 0.0f;
  if (chords) {
    const double k2w = k2 * 1.01 + 1e-4;
    q.chord_slope = static_cast<float>(-s.b / s.a);
    q.chord_k0 = static_cast<float>(k2w / s.a);
    q.chord_k1 = static_cast<float>(det / (s.a * s.a));
  }
  return q;
}

// A Gaussian of standard deviations (s1, s2) px at angle t, the projection's 0.3 px^2
// blur added, centred near the tile at (x0, y0).
Spec randomSpec(std::mt19937& rng, int x0, int y0) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const double s1 = std::exp(std::log(0.25) + U(rng) * std::log(400.0 / 0.25));
  const double s2 = s1 / std::exp(U(rng) * std::log(60.0));
  const double t = U(rng) * 3.141592653589793;
  const double ct = std::cos(t), st = std::sin(t);
  const double sxx = s1 * s1 * ct * ct + s2 * s2 * st * st + 0.3;
  const double syy = s1 * s1 * st * st + s2 * s2 * ct * ct + 0.3;
  const double sxy = (s1 * s1 - s2 * s2) * ct * st;
  const double det = sxx * syy - sxy * sxy;
  Spec s;
  const double reach = std::min(3.0 * s1, 40.0);
  s.mx = x0 + 8.0 + (2.0 * U(rng) - 1.0) * (8.0 + reach);
  s.my = y0 + 8.0 + (2.0 * U(rng) - 1.0) * (8.0 + reach);
  s.a = syy / det;
  s.b = -sxy / det;
  s.c = sxx / det;
  s.o = std::exp(std::log(1.05 / 255.0) + U(rng) * std::log(0.99 * 255.0 / 1.05));
  return s;
}

// G's error against exp in double, relative. Per block (evalLanes) it is the exponent's
// rounding, which for a needle-like Gaussian far from its centre is a few ulp of terms
// much larger than their sum (measured up to 1.1e-4 here), plus exp2's 2e-7. On the
// lattice it is the sum of the first block's three exponents' rounding (each term at most
// ~|kLatticeFloor| = 100, so a few 1e-6 each) and one rounding per product, at most
// 4 + 8 + 4 products in a 16-pixel tile (up to 2.0e-5 measured with four lanes, whose
// block rows are one pixel high, 1.4e-5 with eight).
constexpr double kTolExact = 2.5e-4;
constexpr double kTolLattice = 4e-5;

struct WalkStats {
  long gaussians = 0, on_lattice = 0, lanes_checked = 0;
  double max_rel = 0.0, max_rel_lattice = 0.0;
};

// Walks one Gaussian over the tile at (x0, y0) with this compilation's forEachBlock and
// checks every lane against double precision: the lane's offsets are exact, a pixel is
// visited at most once, every pixel that passes rule 4's rectangle and the alpha
// threshold by more than the path's tolerance (kTolLattice on the lattice, kTolExact off
// it) is visited and touched, none that fails it by that margin is touched, and where it
// passes, G is within that tolerance of exp in double.
void walk(const Spec& s, bool chords, int x0, int y0, WalkStats& st) {
  const TileGaussian<float> g = tileGaussian(s, chords);
  int c0, c1, r0, r1;
  tileSpan(g.px0, g.px1, x0, x0 + kTile, c0, c1);
  tileSpan(g.py0, g.py1, y0, y0 + kTile, r0, r1);
  ++st.gaussians;
  bool lattice = false;
  if (c0 <= c1 && r0 <= r1) {
    Lattice lt;
    const int cb0 = c0 & ~(kBW - 1), cbl = c1 & ~(kBW - 1);
    lattice = latticeFits(g, x0, y0, cb0, cbl, r0 / kBH, r1 / kBH, lt);
    st.on_lattice += lattice;
  }
  const double tol = lattice ? kTolLattice : kTolExact;
  std::vector<int> visits(kTile * kTile, 0), touched(kTile * kTile, 0);
  forEachBlock(g, x0, y0, x0 + kTile, y0 + kTile, [&](int blk, const Lanes& ln, vf dy) {
    for (int i = 0; i < L; ++i) {
      const int k = blk * L + i, row = blockRow(k), col = blockCol(k);
      ++visits[row * kTile + col];
      const float ex = static_cast<float>(x0 + col) + 0.5f - g.mx;
      const float ey = static_cast<float>(y0 + row) + 0.5f - g.my;
      ASSERT_EQ(ln.dx[i], ex);
      ASSERT_EQ(dy[i], ey);
      touched[row * kTile + col] = ln.touches[i] != 0;
      const double dxd = ex, dyd = ey;
      const double G =
          std::exp(-0.5 * (static_cast<double>(g.a) * dxd * dxd + 2.0 * static_cast<double>(g.b) * dxd * dyd +
                           static_cast<double>(g.c) * dyd * dyd));
      const double oG = static_cast<double>(g.o) * G;
      const bool in_rect = std::abs(ex) <= g.hx && std::abs(ey) <= g.hy;
      if (in_rect && oG >= kMinA * (1.0 + tol)) {
        ASSERT_NE(ln.touches[i], 0) << "row " << row << " col " << col << " oG " << oG;
        const double rel = std::abs(static_cast<double>(ln.G[i]) - G) / G;
        (lattice ? st.max_rel_lattice : st.max_rel) = std::max(lattice ? st.max_rel_lattice : st.max_rel, rel);
        ++st.lanes_checked;
        ASSERT_LE(rel, tol) << "row " << row << " col " << col << " G " << G;
        ASSERT_NEAR(ln.alpha[i], std::min(oG, 0.99), 0.99 * tol + 1e-7);
      } else if (!in_rect || oG <= kMinA * (1.0 - tol)) {
        ASSERT_EQ(ln.touches[i], 0) << "row " << row << " col " << col << " oG " << oG;
      }
    }
  });
  for (int row = 0; row < kTile; ++row)
    for (int col = 0; col < kTile; ++col) {
      ASSERT_LE(visits[row * kTile + col], 1);
      const double ex = static_cast<float>(x0 + col) + 0.5f - g.mx;
      const double ey = static_cast<float>(y0 + row) + 0.5f - g.my;
      const double oG = g.o * std::exp(-0.5 * (g.a * ex * ex + 2.0 * g.b * ex * ey + g.c * ey * ey));
      if (std::abs(ex) <= g.hx && std::abs(ey) <= g.hy && oG >= kMinA * (1.0 + tol)) {
        ASSERT_EQ(visits[row * kTile + col], 1) << "row " << row << " col " << col;
        ASSERT_TRUE(touched[row * kTile + col]);
      }
    }
}

// 6000 random Gaussians (round, needle-like, tiny and huge; near the origin and far from
// it; with and without chords) walked and checked; both ways of evaluating G must have
// been exercised, on many lanes.
void checkRandomWalks(const char* label) {
  std::mt19937 rng(7);
  WalkStats st;
  const int origins[][2] = {{0, 0}, {32, 16}, {40960, 24576}};
  for (int n = 0; n < 6000; ++n) {
    const int* org = origins[n % 3];
    walk(randomSpec(rng, org[0], org[1]), (n / 3) % 2 == 1, org[0], org[1], st);
    if (::testing::Test::HasFatalFailure()) return;
  }
  EXPECT_GT(st.on_lattice, st.gaussians / 10);
  EXPECT_LT(st.on_lattice, st.gaussians * 9 / 10);
  EXPECT_GT(st.lanes_checked, 100000);
  EXPECT_GT(st.max_rel_lattice, 0.0);  // the lattice lanes were compared
  std::printf("lattice walk, %s: %ld of %ld Gaussians on the lattice, max relative error %.3g off it, %.3g on it\n",
              label, st.on_lattice, st.gaussians, st.max_rel, st.max_rel_lattice);
}

}  // namespace
}  // namespace saresgs::raster_kernels
