// The rasterizer's execution settings (splat/raster_execution.h): kernel names, what a
// setting resolves to, and that a render runs with the settings it is given.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

#include "raster_test_scenes.h"
#include "splat/rasterize.h"

namespace saresgs {
namespace {

TEST(RasterExecution, ParsesKernelNames) {
  EXPECT_EQ(parseRasterKernels("default"), RasterKernels::kDefault);
  EXPECT_EQ(parseRasterKernels("baseline"), RasterKernels::kBaseline);
  EXPECT_EQ(parseRasterKernels("avx2"), RasterKernels::kAvx2);
  EXPECT_EQ(parseRasterKernels("avx512"), RasterKernels::kAvx512);
  EXPECT_FALSE(parseRasterKernels("AVX2").has_value());
  EXPECT_FALSE(parseRasterKernels("sse").has_value());
  EXPECT_FALSE(parseRasterKernels("").has_value());
}

TEST(RasterExecution, ReportsTheThreadsItRunsOn) {
  EXPECT_EQ(rasterThreadCount(RasterExecution{.threads = 1}), 1);
  EXPECT_EQ(rasterThreadCount(RasterExecution{.threads = 2}), 2);
  EXPECT_GE(rasterThreadCount(RasterExecution{}), 1);  // all cores
  EXPECT_EQ(rasterThreadCount(RasterExecution{.threads = -3}), rasterThreadCount(RasterExecution{}));
}

TEST(RasterExecution, ReportsTheKernelsItUses) {
  EXPECT_STREQ(rasterKernelName(RasterExecution{.kernels = RasterKernels::kBaseline}), "baseline");
  const char* env = std::getenv("SARESGS_RASTER_ISA");
  const bool opt_out = env && std::strcmp(env, "baseline") == 0;
  const bool only_avx2 = env && std::strcmp(env, "avx2") == 0;
  const char* best = rasterCpuHasAvx512() && !only_avx2 ? "avx512" : rasterCpuHasAvx2() ? "avx2" : "baseline";
  EXPECT_STREQ(rasterKernelName(RasterExecution{}), opt_out ? "baseline" : best);
  if (rasterCpuHasAvx2()) {
    EXPECT_STREQ(rasterKernelName(RasterExecution{.kernels = RasterKernels::kAvx2}), "avx2");
  } else {
    EXPECT_THROW(rasterKernelName(RasterExecution{.kernels = RasterKernels::kAvx2}), std::invalid_argument);
  }
  if (rasterCpuHasAvx512()) {
    EXPECT_STREQ(rasterKernelName(RasterExecution{.kernels = RasterKernels::kAvx512}), "avx512");
    EXPECT_TRUE(rasterCpuHasAvx2());  // avx512's forward is avx2's
  } else {
    EXPECT_THROW(rasterKernelName(RasterExecution{.kernels = RasterKernels::kAvx512}), std::invalid_argument);
  }
}

// A render with the default kernels is, bit for bit, the render with the kernels they
// resolve to; asking for kernels the CPU lacks fails instead of running others.
TEST(RasterExecution, RenderRunsWithTheGivenKernels) {
  const Camera cam = test::smallCamera(48, 40);
  const Gaussians g = test::randomScene<double>(200, 1, 4, 1.2).cast<float>();
  RasterSettings s;
  s.sh_degree = 1;
  const RenderResult by_default = rasterize(g, cam, s);
  s.execution.kernels = *parseRasterKernels(rasterKernelName(RasterExecution{}));
  const RenderResult resolved = rasterize(g, cam, s);
  EXPECT_EQ(by_default.rgb.data, resolved.rgb.data);
  EXPECT_EQ(by_default.contributors, resolved.contributors);
  if (!rasterCpuHasAvx2()) {
    s.execution.kernels = RasterKernels::kAvx2;
    EXPECT_THROW(rasterize(g, cam, s), std::invalid_argument);
  }
  if (!rasterCpuHasAvx512()) {
    s.execution.kernels = RasterKernels::kAvx512;
    EXPECT_THROW(rasterize(g, cam, s), std::invalid_argument);
  }
}

}  // namespace
}  // namespace saresgs
