#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "geometry/lifting/extrapolation.h"
#include "geometry/lifting/triangulation.h"

using namespace saresgs;

namespace {

Intrinsics triangulationK(int w = 640, int h = 480, double f = 500) {
  return Intrinsics{.width = w, .height = h, .fx = f, .fy = f * 1.01, .cx = 0.5 * w + 2.5, .cy = 0.5 * h - 1.5};
}

Camera randomRotationCamera(std::mt19937_64& rng, const Eigen::Vector3d& centre) {
  std::normal_distribution<double> n(0, 1);
  const Eigen::Quaterniond q = Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized();
  Camera c = Camera::fromQuaternion(triangulationK(), q, Eigen::Vector3d::Zero());
  c.t = -c.R * centre;
  return c;
}

// The projective image of X, also for points behind the camera (what a matcher could
// report for them); Camera::project refuses those.
Eigen::Vector2d projectAnyway(const Camera& c, const Eigen::Vector3d& X) {
  const Eigen::Vector3d h = c.projectionMatrix() * X.homogeneous();
  return h.head<2>() / h.z();
}

void expectNoNaN(const TriangulatedPoint& p) {
  EXPECT_TRUE(p.X.allFinite());
  EXPECT_TRUE(std::isfinite(p.reprojection_px));
}

}  // namespace

// ------------------------------------------------------------------ extrapolated cameras

TEST(Extrapolation, MovesTheCentreAlongTheCameraAxesAndKeepsRotation) {
  std::mt19937_64 rng(7);
  const Camera c = randomRotationCamera(rng, Eigen::Vector3d(1, -2, 3));
  const Camera e = extrapolatedCamera(c, 0.3, -0.2, 0.5);
  EXPECT_EQ(e.K, c.K);
  EXPECT_TRUE(e.R.isApprox(c.R, 0.0));
  const Eigen::Vector3d expected =
      c.center() + 0.3 * c.R.row(0).transpose() - 0.2 * c.R.row(1).transpose() - 0.5 * c.viewDirection();
  EXPECT_NEAR((e.center() - expected).norm(), 0.0, 1e-12);
  // In camera coordinates the step is (0.3, -0.2, -0.5): backward is -z.
  EXPECT_NEAR((c.toCamera(e.center()) - Eigen::Vector3d(0.3, -0.2, -0.5)).norm(), 0.0, 1e-12);
}

TEST(Extrapolation, DefaultsAreThePaperOffsetsInExtentUnits) {
  std::mt19937_64 rng(8);
  const Camera c = randomRotationCamera(rng, Eigen::Vector3d(0.5, 0.5, 0.5));
  const double extent = 4.5;  // Mip-NeRF 360's typical extent: offsets ~0.25, 0.25, 0.5
  const auto one = extrapolatedCameras(c, extent);
  ASSERT_EQ(one.size(), 1u);
  const Eigen::Vector3d step = c.toCamera(one[0].center());
  EXPECT_NEAR(step.x(), 0.055 * extent, 1e-12);
  EXPECT_NEAR(step.y(), 0.055 * extent, 1e-12);
  EXPECT_NEAR(step.z(), -0.11 * extent, 1e-12);
  EXPECT_NEAR(step.x(), 0.25, 0.01);
  EXPECT_NEAR(step.z(), -0.5, 0.01);
}

TEST(Extrapolation, AllCombinationsAreTheEightXYNeighboursAllBackward) {
  std::mt19937_64 rng(9);
  const Camera c = randomRotationCamera(rng, Eigen::Vector3d(0, 0, 0));
  ExtrapolationOptions o;
  o.all_combinations = true;
  const auto cams = extrapolatedCameras(c, 2.0, o);
  ASSERT_EQ(cams.size(), 8u);
  const double dx = 0.055 * 2, dz = 0.11 * 2;
  std::vector<std::pair<int, int>> signs;
  for (const auto& e : cams) {
    const Eigen::Vector3d s = c.toCamera(e.center());
    EXPECT_NEAR(s.z(), -dz, 1e-12);
    const int sx = static_cast<int>(std::lround(s.x() / dx)), sy = static_cast<int>(std::lround(s.y() / dx));
    EXPECT_NEAR(s.x(), sx * dx, 1e-12);
    EXPECT_NEAR(s.y(), sy * dx, 1e-12);
    signs.emplace_back(sx, sy);
  }
  EXPECT_EQ(signs.front(), std::make_pair(1, 1));  // the default view comes first
  std::sort(signs.begin(), signs.end());
  EXPECT_EQ(std::unique(signs.begin(), signs.end()), signs.end());
  EXPECT_EQ(std::count(signs.begin(), signs.end(), std::make_pair(0, 0)), 0);
}

// ------------------------------------------------------------------------ triangulation

TEST(Triangulation, ExactCorrespondencesRecoverThePoint) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  int solved = 0;
  double worst = 0;
  // Far from the origin too: the world normalisation must keep the digits.
  for (const double offset : {0.0, 1e3}) {
    for (int k = 0; k < 300; ++k) {
      const Eigen::Vector3d o = Eigen::Vector3d::Constant(offset);
      const Eigen::Vector3d X = o + Eigen::Vector3d(u(rng), u(rng), u(rng));
      // Two centres 3-6 units away from X, at least 20 degrees apart as seen from X.
      Eigen::Vector3d d0, d1;
      do {
        d0 = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
        d1 = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
      } while (d0.dot(d1) > std::cos(20 * std::numbers::pi / 180));
      const Eigen::Vector3d c0p = X + (4.5 + 1.5 * u(rng)) * d0, c1p = X + (4.5 + 1.5 * u(rng)) * d1;
      const Camera c0 = Camera::lookAt(triangulationK(), c0p, X + 0.3 * Eigen::Vector3d(u(rng), u(rng), u(rng)));
      const Camera c1 = Camera::lookAt(triangulationK(), c1p, X + 0.3 * Eigen::Vector3d(u(rng), u(rng), u(rng)));
      const auto x0 = c0.project(X), x1 = c1.project(X);
      ASSERT_TRUE(x0 && x1);
      const TriangulatedPoint p = triangulate(c0, c1, {*x0, *x1});
      ASSERT_EQ(p.rejection, Rejection::kNone) << rejectionName(p.rejection);
      const double rel = (p.X - X).norm() / (X - c0.center()).norm();
      worst = std::max(worst, rel);
      EXPECT_LT(rel, 1e-9);
      EXPECT_LT(p.reprojection_px, 1e-6);
      ++solved;
    }
  }
  EXPECT_EQ(solved, 600);
  RecordProperty("worst_relative_error", std::to_string(worst));
}

// Two identical cameras side by side (baseline along x, points at the same depth in both):
// the noise across the (horizontal) epipolar lines, n0 - n1 ~ N(0, 2 sigma^2), is the only
// part that the triangulated point cannot absorb, and optimal triangulation splits it
// evenly: each view's error is |n0 - n1| / 2, so the paper's mean two-view error
// eps = |n0 - n1| / 2 is half-normal with scale sigma / sqrt(2):
//   E[eps] = sigma / sqrt(pi) = 0.564 sigma,  median = 0.6745 sigma / sqrt(2) = 0.477 sigma,
//   P(eps >= 1 px) = P(|N(0,1)| >= sqrt(2) / sigma).
// Normalised DLT is not the optimal method, but in this symmetric setting it should be
// within a few percent of it.
TEST(Triangulation, PixelNoiseGivesTheExpectedReprojectionStatistics) {
  const double sigma = 0.5;
  std::mt19937_64 rng(12);
  std::normal_distribution<double> noise(0, sigma);
  std::uniform_real_distribution<double> u(0, 1);
  const Camera c0 = Camera::fromQuaternion(triangulationK(), Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero());
  Camera c1 = c0;
  c1.t = -c1.R * Eigen::Vector3d(1.0, 0, 0);
  TriangulationOptions o;
  std::vector<double> eps;
  int rejected_reprojection = 0, other = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const double z = 4 + 2 * u(rng);
    // x0 in [250, 600): x1 = x0 - f / z stays >= 125, away from the border.
    const Eigen::Vector2d px(250 + 350 * u(rng), 60 + 360 * u(rng));
    const Eigen::Vector3d X = c0.unproject(px, z);
    Correspondence m{*c0.project(X), *c1.project(X)};
    m.x0 += Eigen::Vector2d(noise(rng), noise(rng));
    m.x1 += Eigen::Vector2d(noise(rng), noise(rng));
    const TriangulatedPoint p = triangulate(c0, c1, m, o);
    expectNoNaN(p);
    if (p.rejection == Rejection::kReprojection)
      ++rejected_reprojection;
    else if (!p.kept())
      ++other;
    if (p.reprojection_px >= 0) eps.push_back(p.reprojection_px);
  }
  ASSERT_EQ(static_cast<int>(eps.size()), n);
  EXPECT_EQ(other, 0);
  double mean = 0;
  for (double e : eps) mean += e;
  mean /= n;
  std::nth_element(eps.begin(), eps.begin() + n / 2, eps.end());
  const double median = eps[n / 2];
  const double mean_expected = sigma / std::sqrt(std::numbers::pi);
  const double median_expected = 0.67449 * sigma / std::sqrt(2.0);
  // Sampling error of the mean at n = 20000 is ~0.3 %; 5 % leaves room for DLT.
  EXPECT_NEAR(mean, mean_expected, 0.05 * mean_expected);
  EXPECT_NEAR(median, median_expected, 0.05 * median_expected);
  const double p_reject = std::erfc(std::sqrt(2.0) / sigma / std::sqrt(2.0));  // P(|N| >= 2.83)
  const double frac = static_cast<double>(rejected_reprojection) / n;
  // Expected ~0.47 % = 93 points; the Poisson spread is ~10 points.
  EXPECT_NEAR(frac, p_reject, 0.4 * p_reject);
  std::cout << "[ noise ] sigma " << sigma << " px: mean " << mean << " (expected " << mean_expected << "), median "
            << median << " (expected " << median_expected << "), rejected by 1 px " << frac << " (expected " << p_reject
            << ")\n";
}

TEST(Triangulation, NearParallelRaysAreRejected) {
  const Camera c0 = Camera::fromQuaternion(triangulationK(), Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero());
  Camera c1 = c0;
  c1.t = -c1.R * Eigen::Vector3d(0.05, 0, 0);  // 5 cm baseline at 10 m: 0.29 degrees
  const Eigen::Vector3d X(0.3, -0.2, 10);
  const TriangulatedPoint p = triangulate(c0, c1, {*c0.project(X), *c1.project(X)});
  EXPECT_EQ(p.rejection, Rejection::kParallelRays);
  expectNoNaN(p);
  // The same point with a 1 m baseline (5.7 degrees) is kept: the check is the angle.
  c1.t = -c1.R * Eigen::Vector3d(1.0, 0, 0);
  EXPECT_TRUE(triangulate(c0, c1, {*c0.project(X), *c1.project(X)}).kept());
  // A lower threshold accepts the narrow pair.
  c1.t = -c1.R * Eigen::Vector3d(0.05, 0, 0);
  TriangulationOptions o;
  o.min_ray_angle_deg = 0.1;
  EXPECT_TRUE(triangulate(c0, c1, {*c0.project(X), *c1.project(X)}, o).kept());
}

TEST(Triangulation, ExactlyParallelRaysAreAtInfinity) {
  // Same rotation, different centres, the same pixel in both: the rays are parallel.
  const Camera c0 = Camera::fromQuaternion(triangulationK(), Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero());
  const Camera c1 = extrapolatedCamera(c0, 0.3, 0.2, 0.5);
  const Eigen::Vector2d x(200.5, 100.5);
  const TriangulatedPoint p = triangulate(c0, c1, {x, x});
  EXPECT_EQ(p.rejection, Rejection::kAtInfinity) << rejectionName(p.rejection);
  expectNoNaN(p);
  EXPECT_EQ(p.reprojection_px, -1);
}

TEST(Triangulation, PointsBehindACameraAreRejected) {
  const Camera c0 = Camera::fromQuaternion(triangulationK(), Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero());
  // Camera 1 looks the other way (rotated 180 degrees about y) from z = 20: a point at
  // z = 25 is in front of camera 0 and behind camera 1.
  Camera c1 = c0;
  c1.R = Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitY()).toRotationMatrix();
  c1.t = -c1.R * Eigen::Vector3d(0.5, 0, 20);
  const Eigen::Vector3d X(0.2, 0.1, 25);
  ASSERT_GT(c0.toCamera(X).z(), 0);
  ASSERT_LT(c1.toCamera(X).z(), 0);
  const Correspondence m{*c0.project(X), projectAnyway(c1, X)};
  ASSERT_TRUE(c1.inImage(m.x1));
  const TriangulatedPoint p = triangulate(c0, c1, m);
  EXPECT_EQ(p.rejection, Rejection::kBehindCamera) << rejectionName(p.rejection);
  expectNoNaN(p);
  // The DLT itself finds the point (it is exact); only the check rejects it.
  const DltSolution s = triangulateDLT(c0.projectionMatrix(), c1.projectionMatrix(), m.x0, m.x1);
  EXPECT_EQ(s.status, Rejection::kNone);
  EXPECT_NEAR((s.X - X).norm(), 0.0, 1e-9 * X.norm());
  // Closer than the near plane of camera 0 counts as behind too.
  TriangulationOptions o;
  o.near = 30;
  Camera c2 = c0;
  c2.t = -c2.R * Eigen::Vector3d(2, 0, 0);
  EXPECT_EQ(triangulate(c0, c2, {*c0.project(X), *c2.project(X)}, o).rejection, Rejection::kBehindCamera);
}

TEST(Triangulation, ZeroBaselineIsRejected) {
  std::mt19937_64 rng(13);
  const Camera c0 = randomRotationCamera(rng, Eigen::Vector3d(1, 2, 3));
  // Same centre, another rotation: every pair of rays meets at the centre.
  const Camera c1 = randomRotationCamera(rng, Eigen::Vector3d(1, 2, 3));
  for (const Camera* other : {&c0, &c1}) {
    const TriangulatedPoint p = triangulate(c0, *other, {{100.5, 200.5}, {300.5, 50.5}});
    EXPECT_EQ(p.rejection, Rejection::kZeroBaseline) << rejectionName(p.rejection);
    expectNoNaN(p);
    EXPECT_EQ(p.X, Eigen::Vector3d::Zero());
  }
}

TEST(Triangulation, DegenerateSystemsAreRejected) {
  const Camera c0 = Camera::fromQuaternion(triangulationK(), Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero());
  Camera c1 = c0;
  c1.t = -c1.R * Eigen::Vector3d(0.2, 0.1, 2.0);  // mostly forward: epipoles inside both images
  // Both points at their epipoles: both rays are the baseline, a whole line of solutions.
  const Eigen::Vector2d e0 = *c0.project(c1.center());
  const Eigen::Vector2d e1 = projectAnyway(c1, c0.center());
  ASSERT_TRUE(c0.inImage(e0) && c1.inImage(e1));
  const TriangulatedPoint p = triangulate(c0, c1, {e0, e1});
  EXPECT_EQ(p.rejection, Rejection::kDegenerate) << rejectionName(p.rejection);
  expectNoNaN(p);
  // A projection matrix without a finite centre (singular left block) or with NaN.
  Eigen::Matrix<double, 3, 4> bad = c1.projectionMatrix();
  bad.col(0).setZero();
  EXPECT_EQ(triangulateDLT(c0.projectionMatrix(), bad, e0, e1).status, Rejection::kDegenerate);
  bad = c1.projectionMatrix();
  bad(1, 3) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(triangulateDLT(c0.projectionMatrix(), bad, e0, e1).status, Rejection::kDegenerate);
}

TEST(Triangulation, CorrespondencesOnOrOutsideTheBorderAreRejected) {
  const Camera c0 = Camera::fromQuaternion(triangulationK(), Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero());
  Camera c1 = c0;
  c1.t = -c1.R * Eigen::Vector3d(1, 0, 0);
  const Eigen::Vector3d X(0.1, 0.1, 5);
  const Correspondence good{*c0.project(X), *c1.project(X)};
  ASSERT_TRUE(triangulate(c0, c1, good).kept());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<Correspondence> bad = {
      {{0.5, 100}, good.x1},    // within 1 px of the left edge
      {good.x0, {100, 479.5}},  // within 1 px of the bottom edge
      {{640, 100}, good.x1},    // on the right edge
      {good.x0, {-3, 100}},     // outside
      {{nan, 100}, good.x1},    // not a number
      {good.x0, {inf, 100}},
  };
  for (const auto& m : bad) {
    const TriangulatedPoint p = triangulate(c0, c1, m);
    EXPECT_EQ(p.rejection, Rejection::kBorder);
    expectNoNaN(p);
  }
  TriangulationOptions o;
  o.border_px = 0;
  EXPECT_NE(triangulate(c0, c1, bad[0], o).rejection, Rejection::kBorder);
}

TEST(Triangulation, RandomInputsNeverProduceNaN) {
  std::mt19937_64 rng(14);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Correspondence> ms;
  for (int i = 0; i < 4000; ++i)
    ms.push_back({{320 + 400 * u(rng), 240 + 300 * u(rng)}, {320 + 400 * u(rng), 240 + 300 * u(rng)}});
  int kinds[kRejectionCount] = {};
  for (int k = 0; k < 20; ++k) {
    const Camera c0 = randomRotationCamera(rng, Eigen::Vector3d(u(rng), u(rng), u(rng)));
    const double scale = std::pow(10.0, 6 * u(rng));  // baselines from 1e-6 to 1e6
    const Camera c1 = randomRotationCamera(rng, c0.center() + scale * Eigen::Vector3d(u(rng), u(rng), u(rng)));
    for (const auto& p : triangulateAll(c0, c1, ms)) {
      expectNoNaN(p);
      ++kinds[static_cast<int>(p.rejection)];
      if (p.kept()) {
        EXPECT_LT(p.reprojection_px, 1.0);
      }
    }
  }
  EXPECT_GT(kinds[static_cast<int>(Rejection::kBorder)], 0);
  EXPECT_GT(kinds[static_cast<int>(Rejection::kReprojection)], 0);
}

TEST(Triangulation, ParallelResultIsInInputOrderAndMatchesTheSerialOne) {
  std::mt19937_64 rng(15);
  std::uniform_real_distribution<double> u(0, 1);
  const Camera c0 = Camera::fromQuaternion(triangulationK(), Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero());
  const Camera c1 = extrapolatedCamera(c0, 0.4, 0.3, 0.8);
  std::vector<Correspondence> ms;
  for (int i = 0; i < 5000; ++i) {
    const Eigen::Vector3d X = c0.unproject({50 + 540 * u(rng), 50 + 380 * u(rng)}, 2 + 8 * u(rng));
    const auto x1 = c1.project(X);
    ms.push_back({*c0.project(X), *x1 + Eigen::Vector2d(u(rng) - 0.5, u(rng) - 0.5)});
  }
  const auto all = triangulateAll(c0, c1, ms);
  ASSERT_EQ(all.size(), ms.size());
  for (std::size_t i = 0; i < ms.size(); ++i) {
    const TriangulatedPoint s = triangulate(c0, c1, ms[i]);
    EXPECT_EQ(all[i].rejection, s.rejection);
    EXPECT_EQ(all[i].X, s.X);
  }
}
