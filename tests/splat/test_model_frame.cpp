// A model between a scene's world frame and its internal one (splat/model_frame.h): the
// round trip, the identity untouched bit for bit, and the same image from either side.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "geometry/scene/scene_frame.h"
#include "raster/raster_test_scenes.h"
#include "splat/model_frame.h"
#include "splat/rasterize.h"

namespace saresgs {
namespace {

TEST(ModelFrame, TheIdentityFrameLeavesTheModelBitForBit) {
  const Gaussians g = test::randomScene<float>(40, 1, 7);
  const Gaussians w = gaussiansToWorld(g, SceneFrame{});
  EXPECT_EQ(std::memcmp(w.means.data(), g.means.data(), g.means.size() * 4), 0);
  EXPECT_EQ(std::memcmp(w.log_scales.data(), g.log_scales.data(), g.log_scales.size() * 4), 0);
  const Gaussians back = gaussiansFromWorld(g, SceneFrame{});
  EXPECT_EQ(std::memcmp(back.means.data(), g.means.data(), g.means.size() * 4), 0);
}

TEST(ModelFrame, RoundTripAndTheSameRenderFromEitherFrame) {
  SceneFrame f;
  f.center = Eigen::Vector3d(30, -20, 5);
  f.scale = 10;
  const Gaussians internal = test::randomScene<float>(60, 1, 11);
  const Gaussians world = gaussiansToWorld(internal, f);
  for (std::size_t i = 0; i < internal.size(); ++i) {
    const Eigen::Vector3d m(internal.means[3 * i], internal.means[3 * i + 1], internal.means[3 * i + 2]);
    const Eigen::Vector3d mw(world.means[3 * i], world.means[3 * i + 1], world.means[3 * i + 2]);
    EXPECT_LT((mw - f.toWorld(m)).norm(), 1e-5);
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(std::exp(world.log_scales[3 * i + k]), 10 * std::exp(internal.log_scales[3 * i + k]), 1e-5);
  }
  EXPECT_EQ(world.rotations, internal.rotations);
  EXPECT_EQ(world.opacities, internal.opacities);
  EXPECT_EQ(world.sh, internal.sh);
  const Gaussians back = gaussiansFromWorld(world, f);
  for (std::size_t j = 0; j < back.means.size(); ++j) {
    EXPECT_NEAR(back.means[j], internal.means[j], 1e-5);
    EXPECT_NEAR(back.log_scales[j], internal.log_scales[j], 1e-6);
  }
  // The world model seen by the world camera is the internal model seen by the internal one.
  const Camera cam_internal = test::smallCamera(32, 24);
  const Camera cam_world = f.toWorld(cam_internal);
  RasterSettings rs;
  rs.sh_degree = 1;
  rs.near_plane = 0.01f * 10;  // the near plane is a distance: it scales with the frame
  const ImageF a = rasterize(world, cam_world, rs).rgb;
  rs.near_plane = 0.01f;
  const ImageF b = rasterize(internal, cam_internal, rs).rgb;
  ASSERT_EQ(a.data.size(), b.data.size());
  double worst = 0, sum = 0;
  for (std::size_t j = 0; j < a.data.size(); ++j) {
    worst = std::max(worst, static_cast<double>(std::abs(a.data[j] - b.data[j])));
    sum += b.data[j];
  }
  EXPECT_GT(sum, 1.0) << "the camera sees the model";
  EXPECT_LT(worst, 2e-3);
}

}  // namespace
}  // namespace saresgs
