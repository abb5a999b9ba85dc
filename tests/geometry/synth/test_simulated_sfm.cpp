#include <gtest/gtest.h>

#include <algorithm>

#include "common/synthetic_options.h"
#include "geometry/synth/write_dataset.h"

using namespace saresgs;

TEST(SimulatedSfm, NoiseOutliersAndTracksAreAsSpecified) {
  const SyntheticScene scene =
      makeSyntheticScene(test::syntheticOptions("room360", 128, 96, /*seed=*/0, /*num_views=*/40));
  ColmapModel model = colmapModelOf(scene);
  SimulatedSfmOptions sim;
  sim.candidates = 6000;
  sim.max_points = 4000;
  simulateSfm(scene, model, sim);
  ASSERT_GT(model.points.size(), 1000u);
  EXPECT_NO_THROW(validateColmapModel(model, "simulated"));

  // Recompute every point's reprojection error from the geometry itself.
  std::vector<double> errors;
  int outliers = 0;
  for (const auto& [id, p] : model.points) {
    ASSERT_GE(p.track.size(), 2u);
    double err = 0;
    for (const auto& e : p.track) {
      const ColmapImage& im = model.images.at(e.image_id);
      EXPECT_EQ(im.point3d_ids.at(e.point2d_idx), id);
      const Camera& cam = scene.cameras[e.image_id - 1];
      // Only train views observe points.
      EXPECT_TRUE(std::find(scene.train.begin(), scene.train.end(), int(e.image_id - 1)) != scene.train.end());
      EXPECT_TRUE(cam.inImage(im.xys[e.point2d_idx]));
      const auto uv = cam.project(p.xyz);
      ASSERT_TRUE(uv) << "point " << id << " is behind a camera that observes it";
      err += (*uv - im.xys[e.point2d_idx]).norm();
    }
    err /= p.track.size();
    EXPECT_NEAR(err, p.error, 1e-9 * (1 + err));
    if (err > 5.0)
      ++outliers;
    else
      errors.push_back(err);
  }
  // About 3 % outliers (a few land near the surface by chance and pass as inliers).
  const double outlier_fraction = static_cast<double>(outliers) / model.points.size();
  EXPECT_GT(outlier_fraction, 0.01);
  EXPECT_LT(outlier_fraction, 0.05);
  // Inlier noise of about 0.5 px mean reprojection error.
  double mean = 0;
  for (double e : errors) mean += e;
  mean /= errors.size();
  EXPECT_GT(mean, 0.3);
  EXPECT_LT(mean, 0.7);
}

TEST(SimulatedSfm, DeterministicForASeed) {
  const SyntheticScene scene =
      makeSyntheticScene(test::syntheticOptions("object", 64, 48, /*seed=*/0, /*num_views=*/12));
  ColmapModel a = colmapModelOf(scene), b = colmapModelOf(scene), c = colmapModelOf(scene);
  SimulatedSfmOptions sim;
  sim.candidates = 2000;
  simulateSfm(scene, a, sim);
  simulateSfm(scene, b, sim);
  sim.seed = 1;
  simulateSfm(scene, c, sim);
  ASSERT_EQ(a.points.size(), b.points.size());
  for (const auto& [id, p] : a.points) EXPECT_EQ(p.xyz, b.points.at(id).xyz);
  EXPECT_NE(a.points.begin()->second.xyz, c.points.begin()->second.xyz);
}
