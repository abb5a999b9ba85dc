// The path-variance selector (nbv/path_variance.h): its score against a brute-force
// double-precision reference on a tiny model, and what it prefers on small made-up scenes:
// a ring's largest gap, a cluster's interior, and nothing that a wall hides.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/pinhole.h"
#include "nbv/path_variance.h"
#include "nbv/selectors.h"
#include "splat/fisher_detail.h"
#include "splat/raster/raster_test_scenes.h"

namespace saresgs {
namespace {

Camera ringCamera(double degrees, double radius = 3.0, int w = 32, int h = 24) {
  const Intrinsics K = test::pinhole(w, h, 0.9 * w);
  const double a = degrees * M_PI / 180;
  return Camera::lookAt(K, Eigen::Vector3d(radius * std::cos(a), radius * std::sin(a), 0.3), Eigen::Vector3d::Zero(),
                        Eigen::Vector3d::UnitZ());
}

// A scene of cameras at `degrees` on a ring about the origin, every one a train view.
Scene pathRingScene(const std::vector<double>& degrees) {
  Scene s;
  for (std::size_t i = 0; i < degrees.size(); ++i) {
    SceneView v;
    v.name = std::to_string(i);
    v.camera = ringCamera(degrees[i]);
    s.views.push_back(v);
    s.train.push_back(static_cast<int>(i));
  }
  return s;
}

// n opaque Gaussians on a sphere of `radius` about `centre` (a Fibonacci lattice): an
// object whose far side its near side hides.
Gaussians sphere(int n, double radius, const Eigen::Vector3d& centre = Eigen::Vector3d::Zero(), float logit = 4.0f) {
  Gaussians g;
  g.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double z = 1 - 2 * (i + 0.5) / n, r = std::sqrt(1 - z * z), phi = i * M_PI * (3 - std::sqrt(5.0));
    const Eigen::Vector3d p = centre + radius * Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z);
    for (int k = 0; k < 3; ++k) {
      g.means[3 * i + k] = static_cast<float>(p[k]);
      g.log_scales[3 * i + k] = static_cast<float>(std::log(1.6 * radius / std::sqrt(n)));
      g.sh[3 * i + k] = static_cast<float>(0.3 * std::sin(i + k));
    }
    g.rotations[4 * i] = 1;
    g.opacities[i] = logit;
  }
  return g;
}

Gaussians join(const Gaussians& a, const Gaussians& b) {
  Gaussians g = a;
  g.means.insert(g.means.end(), b.means.begin(), b.means.end());
  g.log_scales.insert(g.log_scales.end(), b.log_scales.begin(), b.log_scales.end());
  g.rotations.insert(g.rotations.end(), b.rotations.begin(), b.rotations.end());
  g.opacities.insert(g.opacities.end(), b.opacities.begin(), b.opacities.end());
  g.sh.insert(g.sh.end(), b.sh.begin(), b.sh.end());
  return g;
}

double angleOf(const Scene& s, int v) {
  const Eigen::Vector3d c = s.views[static_cast<std::size_t>(v)].camera.center();
  double a = std::atan2(c.y(), c.x()) * 180 / M_PI;
  return a < 0 ? a + 360 : a;
}

// The score written out in double from the per-view information in double: every
// parameter p of the four groups, W_p H_cp / ((H_p + l_g)(H_p + H_cp + l_g)), l_g kappa
// times the median of the group's nonzero held information (at least lambda).
std::vector<double> referenceScores(const GaussiansD& g, const RasterSettings& s, const Scene& scene,
                                    const std::vector<int>& held, const std::vector<int>& candidates, double lambda,
                                    double kappa) {
  GaussiansD H = g.zerosLike(), W = g.zerosLike();
  for (int v : held) addViewInformationT(g, scene.views[static_cast<std::size_t>(v)].camera, s, H);
  std::vector<GaussiansD> Hc;
  for (int c : candidates) {
    Hc.push_back(g.zerosLike());
    addViewInformationT(g, scene.views[static_cast<std::size_t>(c)].camera, s, Hc.back());
  }
  std::vector<std::vector<double>*> groups_h{&H.means, &H.log_scales, &H.opacities, &H.sh};
  std::vector<double> damping;
  for (const auto* h : groups_h) {
    std::vector<double> nz;
    for (double x : *h)
      if (x > 0) nz.push_back(x);
    std::sort(nz.begin(), nz.end());
    damping.push_back(nz.empty() ? lambda : std::max(lambda, kappa * nz[nz.size() / 2]));
  }
  auto arrays = [](GaussiansD& x) {
    return std::vector<std::vector<double>*>{&x.means, &x.log_scales, &x.opacities, &x.sh};
  };
  for (std::size_t k = 0; k < 4; ++k) {
    std::vector<double>& w = *arrays(W)[k];
    for (std::size_t p = 0; p < w.size(); ++p) {
      w[p] = (*arrays(H)[k])[p];
      for (auto& c : Hc) w[p] += (*arrays(c)[k])[p];
    }
  }
  std::vector<double> out;
  for (auto& c : Hc) {
    double score = 0;
    for (std::size_t k = 0; k < 4; ++k)
      for (std::size_t p = 0; p < arrays(c)[k]->size(); ++p) {
        const double hc = (*arrays(c)[k])[p], h = (*arrays(H)[k])[p], w = (*arrays(W)[k])[p], l = damping[k];
        score += w * hc / ((h + l) * (h + hc + l));
      }
    out.push_back(score);
  }
  return out;
}

TEST(PathVariance, ScoreEqualsTheDoublePrecisionReference) {
  const GaussiansD gd = test::randomScene<double>(30, 1, 11, 0.7);
  const Gaussians g = gd.cast<float>();
  RasterSettings s;
  s.sh_degree = 1;
  s.background = {0.3f, 0.1f, 0.2f};
  const Scene scene = pathRingScene({0, 40, 95, 150, 210, 260, 320});
  const std::vector<int> held{0, 3}, candidates{1, 2, 4, 5, 6};
  for (double kappa : {0.0, 0.01, 1.0}) {
    const std::vector<double> ref = referenceScores(gd, s, scene, held, candidates, 1e-6, kappa);
    // The candidates' information: all kept between the passes, none (computed again), or
    // the first two kept and the rest computed again (a budget of two models' information).
    const std::size_t one = (g.means.size() + g.log_scales.size() + g.opacities.size() + g.sh.size()) * sizeof(float);
    for (std::size_t keep : {std::size_t{1} << 30, std::size_t{0}, 2 * one}) {
      const std::vector<double> got = pathVarianceScores(g, s, scene, held, candidates, {1e-6, kappa, keep});
      ASSERT_EQ(got.size(), ref.size());
      for (std::size_t i = 0; i < ref.size(); ++i) {
        EXPECT_GT(ref[i], 0.0);
        EXPECT_NEAR(got[i], ref[i], 2e-4 * ref[i]) << "kappa " << kappa << " candidate " << i << " keep " << keep;
      }
    }
  }
}

TEST(PathVariance, RelativeDampingIsKappaTimesEachGroupsMedianAboveTheFloor) {
  Gaussians H;
  H.resize(4);
  H.means = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11};  // nonzero median 6
  H.opacities = {0, 0, 0, 0};                        // nothing seen: the floor
  H.log_scales = {5, 5, 5, 5, 5, 5, 5, 5, 5, 5, 5, 5};
  H.sh = {1e-12f, 1e-12f, 1e-12f, 1e-12f, 1e-12f, 1e-12f, 1e-12f, 1e-12f, 1e-12f, 1e-12f, 1e-12f, 1e-12f};
  const GroupDamping l = relativeDamping(H, 0.1, 1e-6);
  EXPECT_DOUBLE_EQ(l.means, 0.1 * 6);
  EXPECT_DOUBLE_EQ(l.log_scales, 0.5);
  EXPECT_DOUBLE_EQ(l.opacities, 1e-6);
  EXPECT_DOUBLE_EQ(l.sh, 1e-6);  // kappa x median below the floor
  const GroupDamping fixed = relativeDamping(H, 0.0, 1e-6);
  EXPECT_DOUBLE_EQ(fixed.means, 1e-6);
  EXPECT_DOUBLE_EQ(fixed.log_scales, 1e-6);
}

// The diagnostic of FisherRF's damping: the share of a trace score from parameters whose
// held information is below 1e-3 of their group's median.
TEST(PathVariance, UnseenShareIsTheScoreOfWhatNoHeldViewSaw) {
  Gaussians H, Hv;
  H.resize(4);
  Hv.resize(4);
  // Means: held information 1, 1, 1e-5 (unseen: below 1e-3 x the median 1), and 0.
  H.means = {1, 1, 1, 1, 1, 1, 1e-5f, 1e-5f, 1e-5f, 0, 0, 0};
  Hv.means = {1, 0, 0, 0, 0, 0, 1e-5f, 0, 0, 1e-6f, 0, 0};
  const double lambda = 1e-6;
  const double seen = 1 / (1 + lambda), unseen = 1e-5 / (1e-5 + lambda) + 1e-6 / lambda;
  EXPECT_NEAR(unseenShare(Hv, H, lambda), unseen / (seen + unseen), 1e-6);
  // Opacities nobody saw at all: all of their score is unseen.
  Gaussians Ho = H.zerosLike(), Hvo = H.zerosLike();
  Hvo.opacities = {0.5f, 0, 0, 0};
  EXPECT_DOUBLE_EQ(unseenShare(Hvo, Ho, lambda), 1.0);
  EXPECT_DOUBLE_EQ(unseenShare(H.zerosLike(), H, lambda), 0.0);
}

// Held views on half of a ring: the candidate taken lies in the other half's middle, the
// largest gap, and not next to a held view.
TEST(PathVariance, ARingsLargestGapIsTaken) {
  std::vector<double> deg;
  for (int a = 0; a < 360; a += 15) deg.push_back(a);
  const Scene scene = pathRingScene(deg);
  std::vector<int> held, candidates;
  for (int i = 0; i < static_cast<int>(deg.size()); ++i)
    (deg[static_cast<std::size_t>(i)] <= 150 ? held : candidates).push_back(i);
  RasterSettings s;
  s.sh_degree = 0;
  const Gaussians g = sphere(400, 0.8);
  for (double kappa : {0.0, 0.01}) {
    const std::vector<double> score = pathVarianceScores(g, s, scene, held, candidates, {1e-6, kappa});
    const double a = angleOf(scene, candidates[argmaxScore(score, candidates)]);
    EXPECT_GE(a, 210.0) << "kappa " << kappa;
    EXPECT_LE(a, 300.0) << "kappa " << kappa;
  }
}

// Most of the path lies in one cluster of views: the view taken is inside it, not at
// its edge, and not one of the lone views elsewhere.
TEST(PathVariance, AClusteredPathGetsAViewInsideTheCluster) {
  // Held at 270 degrees; the cluster a quarter turn from it, the lone views across from it
  // (where the most is unseen: without the pool's weight W they win).
  std::vector<double> deg{270};                             // held
  for (int a = 0; a <= 48; a += 4) deg.push_back(a);        // the cluster: 13 views
  for (double a : {110.0, 140.0, 170.0}) deg.push_back(a);  // lone views
  const Scene scene = pathRingScene(deg);
  std::vector<int> candidates;
  for (int i = 1; i < static_cast<int>(deg.size()); ++i) candidates.push_back(i);
  RasterSettings s;
  s.sh_degree = 0;
  const Gaussians g = sphere(400, 0.8);
  const std::vector<double> score = pathVarianceScores(g, s, scene, {0}, candidates, {1e-6, 0.01});
  const double a = angleOf(scene, candidates[argmaxScore(score, candidates)]);
  EXPECT_GT(a, 0.5);
  EXPECT_LT(a, 47.5);
}

// A view whose line of sight a wall blocks gains nothing from what lies behind the wall:
// with the object behind it or without, its score is the same; without the wall the object
// is most of the score.
TEST(PathVariance, NothingHiddenBehindAWallIsRewarded) {
  // No view held (what a held view saw of the wall would change with the object in front
  // of it); the candidate looks from the back.
  const Scene scene = pathRingScene({180});
  RasterSettings s;
  s.sh_degree = 0;
  const Gaussians object = sphere(300, 0.5);
  Gaussians gone = object;
  for (float& o : gone.opacities) o = -30.0f;  // the same Gaussians, transparent
  // The wall: a dense opaque sheet across the back camera's view, halfway to the object.
  Gaussians wall;
  const int n = 24;
  wall.resize(static_cast<std::size_t>(n * n));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const std::size_t k = static_cast<std::size_t>(i * n + j);
      const float y = -1.6f + 3.2f * (i + 0.5f) / n, z = 0.3f - 1.6f + 3.2f * (j + 0.5f) / n;
      wall.means[3 * k] = -1.5f;
      wall.means[3 * k + 1] = y;
      wall.means[3 * k + 2] = z;
      for (int c = 0; c < 3; ++c) wall.log_scales[3 * k + c] = std::log(0.12f);
      wall.rotations[4 * k] = 1;
      wall.opacities[k] = 6.0f;
    }
  auto score = [&](const Gaussians& g) { return pathVarianceScores(g, s, scene, {}, {0}, {1e-6, 0.01})[0]; };
  const double walled = score(join(wall, object)), walled_empty = score(join(wall, gone));
  EXPECT_NEAR(walled, walled_empty, 1e-3 * walled_empty) << "the object behind the wall changed the score";
  const double open = score(object), open_empty = score(gone);
  EXPECT_GT(open, 100 * std::max(open_empty, 1e-30)) << "without the wall the object must count";
}

}  // namespace
}  // namespace saresgs
