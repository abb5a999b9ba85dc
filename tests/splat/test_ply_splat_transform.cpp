// Our .ply files read by a real consumer: PlayCanvas splat-transform (npm), installed by
// scripts/install_node_tools.sh into <build>/node_tools. The tests fail (never skip) when
// it is missing.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

#include "common/test_support.h"
#include "splat/ply.h"
#include "splat/splat_file.h"

using namespace saresgs;
using saresgs::test::TempDir;

namespace {

// scripts/install_node_tools.sh installs it into <repo>/build/node_tools; a second build
// folder (the sanitizer build, scripts/test_sanitizers.sh) uses that one.
const std::string kTool = [] {
  const std::string own = std::string(SARESGS_BINARY_DIR) + "/node_tools/node_modules/.bin/splat-transform";
  const std::string main = std::string(SARESGS_SOURCE_DIR) + "/build/node_tools/node_modules/.bin/splat-transform";
  return std::filesystem::exists(own) || !std::filesystem::exists(main) ? own : main;
}();

::testing::AssertionResult toolPresent() {
  if (std::filesystem::exists(kTool)) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "splat-transform not found at " << kTool
         << "; run scripts/install_node_tools.sh (installs @playcanvas/splat-transform@3)";
}

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

struct ToolRun {
  int rc = -1;
  std::string out;  // stdout and stderr together
};

ToolRun runTool(const std::string& args) {
  ToolRun r;
  const std::string cmd = quote(kTool) + " " + args + " 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  std::size_t got;
  while ((got = std::fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, got);
  const int status = ::pclose(p);
  r.rc = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// Values inside the ranges SPZ quantizes without clamping (colours, SH in [-1, 1]).
Gaussians randomSplatModel(std::size_t n, int degree, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> pos(-2.0f, 3.0f), u(-1.0f, 1.0f), ls(-5.0f, -1.0f);
  Gaussians g;
  g.max_sh_degree = degree;
  g.resize(n);
  for (auto& v : g.means) v = pos(rng);
  for (auto& v : g.log_scales) v = ls(rng);
  for (auto& v : g.rotations) v = u(rng);
  for (auto& v : g.opacities) v = 3.0f * u(rng);
  for (auto& v : g.sh) v = 0.9f * u(rng);
  return g;
}

double extent(const Gaussians& g) {
  double lo[3] = {1e30, 1e30, 1e30}, hi[3] = {-1e30, -1e30, -1e30};
  for (std::size_t i = 0; i < g.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], double(g.means[3 * i + a]));
      hi[a] = std::max(hi[a], double(g.means[3 * i + a]));
    }
  return std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                   (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

double sigmoid(double x) { return 1.0 / (1.0 + std::exp(-x)); }

}  // namespace

TEST(SplatTransform, InfoReportsOurGaussianCountAndShBands) {
  ASSERT_TRUE(toolPresent());
  TempDir dir;
  for (int degree : {3, 0}) {
    const Gaussians g = randomSplatModel(777, degree, 10 + degree);
    const std::string in = dir.file("in" + std::to_string(degree) + ".ply");
    writeGaussiansPly(in, g);
    const ToolRun r = runTool(quote(in) + " --info null");
    ASSERT_EQ(r.rc, 0) << r.out;
    EXPECT_NE(r.out.find("gaussian: yes"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("gaussians: 777"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("sh bands: " + std::to_string(degree)), std::string::npos) << r.out;
  }
}

TEST(SplatTransform, SpzRoundTripKeepsCountAndPositions) {
  ASSERT_TRUE(toolPresent());
  TempDir dir;
  for (int degree : {3, 0}) {
    SCOPED_TRACE("degree " + std::to_string(degree));
    const Gaussians g = randomSplatModel(1500, degree, 20 + degree);
    const std::string in = dir.file("in.ply"), spz = dir.file("out.spz"), back = dir.file("back.ply");
    writeGaussiansPly(in, g);
    ToolRun r = runTool("-w " + quote(in) + " " + quote(spz));
    ASSERT_EQ(r.rc, 0) << r.out;
    r = runTool("-w " + quote(spz) + " " + quote(back));
    ASSERT_EQ(r.rc, 0) << r.out;
    const Gaussians b = readGaussiansPly(back);
    ASSERT_EQ(b.size(), g.size());
    EXPECT_EQ(b.max_sh_degree, degree);
    const double tol = 1e-3 * extent(g);
    double max_pos = 0, max_scale = 0, max_alpha = 0, max_dc = 0, max_rest = 0, min_dot = 1;
    const int K = g.shCoeffs();
    for (std::size_t i = 0; i < g.size(); ++i) {
      for (int a = 0; a < 3; ++a) {
        max_pos = std::max(max_pos, std::abs(double(b.means[3 * i + a]) - g.means[3 * i + a]));
        max_scale = std::max(max_scale, std::abs(double(b.log_scales[3 * i + a]) - g.log_scales[3 * i + a]));
      }
      max_alpha = std::max(max_alpha, std::abs(sigmoid(b.opacities[i]) - sigmoid(g.opacities[i])));
      for (int c = 0; c < 3; ++c)
        max_dc = std::max(max_dc, std::abs(double(b.sh[i * K * 3 + c]) - g.sh[i * K * 3 + c]));
      for (int k = 1; k < K; ++k)
        for (int c = 0; c < 3; ++c)
          max_rest = std::max(max_rest, std::abs(double(b.sh[(i * K + k) * 3 + c]) - g.sh[(i * K + k) * 3 + c]));
      // Quaternions: SPZ stores them normalised, up to sign; w first in both of ours.
      double na = 0, nb = 0, dot = 0;
      for (int a = 0; a < 4; ++a) {
        na += double(g.rotations[4 * i + a]) * g.rotations[4 * i + a];
        nb += double(b.rotations[4 * i + a]) * b.rotations[4 * i + a];
        dot += double(g.rotations[4 * i + a]) * b.rotations[4 * i + a];
      }
      min_dot = std::min(min_dot, std::abs(dot) / std::sqrt(na * nb));
    }
    EXPECT_LE(max_pos, tol);
    // SPZ quantisation: log-scale (s + 10) * 16 in 8 bits, sigmoid(opacity) and
    // 0.15 * dc + 0.5 in 8 bits, higher SH as (v * 128 + 128) in 8 bits rounded to 5 bits
    // (band 1) or 4 bits (bands 2, 3). Limits: half a step with some slack; for the
    // higher SH, half a 4-bit step after the 8-bit rounding, (8 + 0.5) / 128 = 0.066.
    EXPECT_LE(max_scale, 0.04);
    EXPECT_LE(max_alpha, 0.004);
    EXPECT_LE(max_dc, 0.02);
    EXPECT_LE(max_rest, 0.07);
    EXPECT_GE(min_dot, 0.99);
    std::printf(
        "  degree %d: max position error %.3g (limit %.3g), log-scale %.3g, opacity %.3g, "
        "dc %.3g, rest %.3g, min |cos| quaternion %.6f\n",
        degree, max_pos, tol, max_scale, max_alpha, max_dc, max_rest, min_dot);
  }
}

// splat-transform's --filter-harmonics keeps the lowest bands by its own reading of the
// f_rest layout (channel-major, as 3DGS writes it). If our writer used any other order,
// the band-1 coefficients it keeps would not be ours.
TEST(SplatTransform, FilterHarmonicsKeepsOurBandOneCoefficients) {
  ASSERT_TRUE(toolPresent());
  TempDir dir;
  const Gaussians g = randomSplatModel(300, 3, 30);
  const std::string in = dir.file("in.ply"), out = dir.file("h1.ply");
  writeGaussiansPly(in, g);
  const ToolRun r = runTool("-w " + quote(in) + " -H 1 " + quote(out));
  ASSERT_EQ(r.rc, 0) << r.out;
  const Gaussians b = readGaussiansPly(out);
  ASSERT_EQ(b.size(), g.size());
  ASSERT_EQ(b.max_sh_degree, 1);
  for (std::size_t i = 0; i < g.size(); ++i) {
    for (int k = 0; k < 4; ++k)
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(b.sh[(i * 4 + k) * 3 + c], g.sh[(i * 16 + k) * 3 + c])
            << "Gaussian " << i << " coefficient " << k << " channel " << c;
    for (int a = 0; a < 3; ++a) ASSERT_EQ(b.means[3 * i + a], g.means[3 * i + a]);
    ASSERT_EQ(b.opacities[i], g.opacities[i]);
  }
}

// The HTML report's compressed form (splat/splat_file.h) read by splat-transform: every
// Gaussian comes back, positions exactly, the rest within the format's 8-bit steps.
TEST(SplatTransform, ReadsOurSplatFileAsWritten) {
  ASSERT_TRUE(toolPresent());
  TempDir dir;
  Gaussians g = randomSplatModel(1200, 3, 31);
  g.rotations[0] = g.rotations[1] = g.rotations[2] = g.rotations[3] = 0;  // a zero quaternion: identity
  const std::string bytes = splatFileBytes(g);
  ASSERT_EQ(bytes.size(), g.size() * kSplatRecordBytes);
  const std::string in = dir.file("model.splat"), back = dir.file("back.ply");
  {
    std::FILE* f = std::fopen(in.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    ASSERT_EQ(std::fwrite(bytes.data(), 1, bytes.size(), f), bytes.size());
    std::fclose(f);
  }
  const ToolRun r = runTool("-w " + quote(in) + " " + quote(back));
  ASSERT_EQ(r.rc, 0) << r.out;
  const Gaussians b = readGaussiansPly(back);
  ASSERT_EQ(b.size(), g.size());
  const int K = g.shCoeffs(), Kb = b.shCoeffs();
  double max_pos = 0, max_scale = 0, max_alpha = 0, max_colour = 0, min_dot = 1;
  for (std::size_t i = 0; i < g.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      max_pos = std::max(max_pos, std::abs(double(b.means[3 * i + a]) - g.means[3 * i + a]));
      max_scale = std::max(max_scale, std::abs(double(b.log_scales[3 * i + a]) - g.log_scales[3 * i + a]));
    }
    max_alpha = std::max(max_alpha, std::abs(sigmoid(b.opacities[i]) - sigmoid(g.opacities[i])));
    for (int c = 0; c < 3; ++c) {
      const double want = std::clamp(0.5 + kShC0 * g.sh[i * K * 3 + c], 0.0, 1.0);
      max_colour = std::max(max_colour, std::abs(0.5 + kShC0 * b.sh[i * Kb * 3 + c] - want));
    }
    double na = 0, nb = 0, dot = 0;
    const bool zero = i == 0;
    for (int a = 0; a < 4; ++a) {
      const double ga = zero ? (a == 0 ? 1.0 : 0.0) : g.rotations[4 * i + a];
      na += ga * ga;
      nb += double(b.rotations[4 * i + a]) * b.rotations[4 * i + a];
      dot += ga * b.rotations[4 * i + a];
    }
    min_dot = std::min(min_dot, std::abs(dot) / std::sqrt(na * nb));
  }
  EXPECT_EQ(max_pos, 0.0);
  EXPECT_LE(max_scale, 1e-5);
  // 8 bits: half a step of 1/255 plus splat-transform's own float rounding
  EXPECT_LE(max_alpha, 0.6 / 255.0);
  EXPECT_LE(max_colour, 0.6 / 255.0);
  // rotation components in steps of 1/128
  EXPECT_GE(min_dot, 0.995);
  std::printf("  .splat: log-scale %.3g, opacity %.3g, colour %.3g, min |cos| quaternion %.6f\n", max_scale, max_alpha,
              max_colour, min_dot);
}
