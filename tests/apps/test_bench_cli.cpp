// Runs `saresgs bench occupancy` on a tiny scene: what it prints is one JSON line a
// script can read, with the measured timings, the grid it measured them on and the
// machine. The timings' values are not checked (speed is not a test property).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "common/run_command.h"
#include "common/test_support.h"

using saresgs::test::runCli;

namespace {

using Result = saresgs::test::CommandResult;

// A benchmark's whole output is one JSON line: parsed into j.
::testing::AssertionResult oneJsonLine(const Result& r, nlohmann::json& j) {
  if (r.code != 0) return ::testing::AssertionFailure() << "exit " << r.code << ": " << r.output;
  if (r.output.empty() || r.output.find('\n') != r.output.size() - 1)
    return ::testing::AssertionFailure() << "not one line: " << r.output;
  try {
    j = nlohmann::json::parse(r.output);
  } catch (const std::exception& e) {
    return ::testing::AssertionFailure() << e.what() << ": " << r.output;
  }
  return ::testing::AssertionSuccess();
}

}  // namespace

TEST(BenchCli, OccupancyPrintsOneJsonLineWithTheMeasuredParts) {
  // One line, nothing else (stdout and stderr together).
  nlohmann::json j;
  ASSERT_TRUE(
      oneJsonLine(runCli("bench occupancy --width 32 --height 24 --points 400 --resolution 16 --threads 1"), j));
  ASSERT_TRUE(j.is_object()) << j;

  EXPECT_EQ(j.at("benchmark"), "occupancy");
  EXPECT_EQ(j.at("width"), 32);
  EXPECT_EQ(j.at("height"), 24);
  EXPECT_EQ(j.at("resolution"), 16);
  EXPECT_EQ(j.at("threads"), 1);
  const auto sfm = j.at("sfm_points").get<std::size_t>();
  EXPECT_GT(sfm, 0u);
  EXPECT_LE(sfm, 400u);
  EXPECT_GT(j.at("cameras").get<int>(), 0);
  // The grid it timed is not empty: timings of an empty grid would mean nothing.
  EXPECT_GT(j.at("coarse_voxels").get<std::size_t>(), 0u);
  EXPECT_GE(j.at("scene_voxels").get<std::size_t>(), j.at("coarse_voxels").get<std::size_t>());
  EXPECT_GT(j.at("observed_points").get<std::size_t>(), 0u);
  EXPECT_LE(j.at("observed_scene_voxels").get<std::size_t>(), j.at("scene_voxels").get<std::size_t>());
  const double f = j.at("observed_fraction").get<double>();
  EXPECT_GE(f, 0.0);
  EXPECT_LE(f, 1.0);
  for (const char* k : {"scene_grid", "add_observed", "embree_bvh"}) {
    ASSERT_TRUE(j.at("stage_ms").contains(k)) << k;
    EXPECT_GE(j["stage_ms"][k].get<double>(), 0.0) << k;
  }
  for (const char* k : {"frustum_set", "visible_set_stride4", "visible_set_stride1", "score_exact",
                        "score_hashed_2pow19", "score_hashed_2pow11", "score_dense_2pow19_1thread"}) {
    ASSERT_TRUE(j.at("per_candidate_ms").contains(k)) << k;
    EXPECT_GE(j["per_candidate_ms"][k].get<double>(), 0.0) << k;
  }
  for (const char* k : {"scene_vdb", "observed_vdb", "scene_index"}) {
    ASSERT_TRUE(j.at("memory_kb").contains(k)) << k;
    EXPECT_GT(j["memory_kb"][k].get<double>(), 0.0) << k;
  }
  EXPECT_GT(j.at("peak_rss_mb").get<double>(), 0.0);
  EXPECT_FALSE(j.at("cpu").get<std::string>().empty());
}

TEST(BenchCli, OccupancyRejectsABadOptionValueByName) {
  Result r = runCli("bench occupancy --resolution 0");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.output.find("--resolution"), std::string::npos) << r.output;

  r = runCli("bench occupancy --points many");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.output.find("--points"), std::string::npos) << r.output;
}

TEST(BenchCli, FisherPrintsOneJsonLineWithTheRatioToTheBackwardPass) {
  nlohmann::json j;
  ASSERT_TRUE(
      oneJsonLine(runCli("bench fisher --width 40 --height 32 --gaussians 300 --threads 1 --steps 3 --warmup 1"), j));
  EXPECT_EQ(j.at("benchmark"), "fisher");
  EXPECT_EQ(j.at("width"), 40);
  EXPECT_EQ(j.at("gaussians"), 300);
  EXPECT_EQ(j.at("threads"), 1);
  EXPECT_FALSE(j.at("kernels").get<std::string>().empty());
  for (const char* k : {"fisher_ms", "view_information_ms", "forward_ms", "backward_ms", "fisher_to_backward_ratio"})
    EXPECT_GT(j.at(k).get<double>(), 0.0) << k;
  // The scene it timed is seen: an empty view would time nothing.
  EXPECT_GT(j.at("information_sum").get<double>(), 0.0);
  EXPECT_GT(j.at("peak_rss_mb").get<double>(), 0.0);
}

// SARESGS_RASTER_ISA picks the kernels a process's default resolves to: the avx512 set's
// information equals the avx2 set's to the last printed digit (the two are bit-identical),
// and a name that is no kernel set's is an error that names the variable.
TEST(BenchCli, FisherKernelsFromTheEnvironment) {
  const std::string args = " bench fisher --width 40 --height 32 --gaussians 300 --threads 1 --steps 1 --warmup 0";
  auto withIsa = [&](const std::string& isa) {
    return saresgs::test::runCommand("SARESGS_RASTER_ISA=" + isa + " " + std::string(SARESGS_CLI) + args);
  };
  nlohmann::json base, by_default;
  ASSERT_TRUE(oneJsonLine(withIsa("baseline"), base));
  EXPECT_EQ(base.at("kernels"), "baseline");
  ASSERT_TRUE(oneJsonLine(runCli(args), by_default));
  const std::string best = by_default.at("kernels");
  if (best != "baseline") {
    nlohmann::json avx2;
    ASSERT_TRUE(oneJsonLine(withIsa("avx2"), avx2));
    EXPECT_EQ(avx2.at("kernels"), "avx2");
    EXPECT_EQ(avx2.at("information_sum").get<double>(), by_default.at("information_sum").get<double>());
    // The baseline's four lanes round differently, to float precision.
    EXPECT_NEAR(base.at("information_sum").get<double>(), avx2.at("information_sum").get<double>(),
                1e-4 * avx2.at("information_sum").get<double>());
  }
  const Result bad = withIsa("sse4");
  EXPECT_NE(bad.code, 0) << bad.output;
  EXPECT_NE(bad.output.find("SARESGS_RASTER_ISA='sse4'"), std::string::npos) << bad.output;
  EXPECT_NE(bad.output.find("expected baseline, avx2, avx512 or default"), std::string::npos) << bad.output;
}

TEST(BenchCli, StepReportsAllocationsPageFaultsAndTheFloor) {
  nlohmann::json j;
  ASSERT_TRUE(
      oneJsonLine(runCli("bench step --width 40 --height 32 --gaussians 300 --threads 1 --steps 3 --warmup 1"), j));
  EXPECT_GE(j.at("allocations_per_step").get<double>(), 0.0);
  EXPECT_GE(j.at("page_faults_per_step").get<double>(), 0.0);
  // Pairs are the contributors of every pixel; the floor is a positive time per pair and
  // the fraction its ratio to the render's (finite: the scene is seen).
  EXPECT_NEAR(j.at("pairs_per_step").get<double>(), j.at("mean_contributors_per_pixel").get<double>() * 40 * 32, 1e-6);
  EXPECT_GT(j.at("pairs_per_step").get<double>(), 0.0);
  EXPECT_GT(j.at("floor_ns_per_pair").get<double>(), 0.0);
  EXPECT_GT(j.at("ns_per_pair_core").at("render").get<double>(), 0.0);
  EXPECT_NEAR(j.at("render_fraction_of_floor").get<double>(),
              j["floor_ns_per_pair"].get<double>() / j["ns_per_pair_core"]["render"].get<double>(), 1e-9);
}

// `bench train` on a tiny written scene: whole iterations by the trainer's stages, which
// with "other" add up to the mean iteration, beside the same-size `bench step`.
TEST(BenchCli, TrainTimesRealIterationsByStageBesideTheSameSizeStep) {
  saresgs::test::TempDir d;
  const std::string data = d.file("tiny");
  Result r = runCli("scene --layout object --views 12 --width 48 --height 32 --out " + data);
  ASSERT_EQ(r.code, 0) << r.output;
  r = saresgs::test::runCommand(std::string(SARESGS_CLI) + " bench train --dataset " + data +
                                " --iterations 6 --warmup 2 --compare-steps 2 --threads 1 2>/dev/null");
  nlohmann::json j;
  ASSERT_TRUE(oneJsonLine(r, j));
  EXPECT_EQ(j.at("benchmark"), "train");
  EXPECT_EQ(j.at("iterations"), 6);
  EXPECT_EQ(j.at("width"), 48);
  EXPECT_EQ(j.at("threads"), 1);
  EXPECT_GT(j.at("gaussians_end").get<int>(), 0);
  EXPECT_GT(j.at("mean_contributors_per_pixel").get<double>(), 0.0);
  double sum = 0;
  for (const char* k : {"render", "loss", "backward", "adam", "densify", "other"}) {
    ASSERT_TRUE(j.at("stage_ms").contains(k)) << k;
    sum += j["stage_ms"][k].get<double>();
  }
  EXPECT_NEAR(sum, j.at("mean_iteration_ms").get<double>(), 1e-6 * (1 + sum));
  for (const char* k : {"render", "loss", "backward", "adam"}) EXPECT_GE(j["stage_ms"][k].get<double>(), 0.0) << k;
  EXPECT_GT(j.at("bench_step_same_size").at("median_ms").get<double>(), 0.0);
  EXPECT_EQ(j.at("bench_step_same_size").at("mean_contributors_per_pixel").is_number(), true);
  EXPECT_GE(j.at("allocations_per_iteration").get<double>(), 0.0);

  EXPECT_EQ(j.at("residual"), false);
  EXPECT_FALSE(j.contains("plain"));

  // --residual: the residual trainer beside a plain one from the same start, each by stage.
  r = saresgs::test::runCommand(std::string(SARESGS_CLI) + " bench train --dataset " + data +
                                " --residual --iterations 13 --warmup 1 --compare-steps 2 --threads 1 2>/dev/null");
  ASSERT_TRUE(oneJsonLine(r, j));
  EXPECT_EQ(j.at("residual"), true);
  ASSERT_TRUE(j.contains("plain"));
  const nlohmann::json& p = j["plain"];
  for (const nlohmann::json* t : std::initializer_list<const nlohmann::json*>{&j, &p}) {
    double total = 0;
    for (const char* k : {"render", "loss", "backward", "adam", "densify", "other"})
      total += t->at("stage_ms").at(k).get<double>();
    EXPECT_NEAR(total, t->at("mean_iteration_ms").get<double>(), 1e-6 * (1 + total));
    EXPECT_GT(t->at("mean_iteration_ms").get<double>(), 0.0);
  }
  EXPECT_NEAR(j.at("residual_to_plain_ratio").get<double>(),
              j["mean_iteration_ms"].get<double>() / p["mean_iteration_ms"].get<double>(), 1e-9);

  r = runCli("bench train --dataset " + d.file("missing") + " --iterations 2");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.output.find("missing"), std::string::npos) << r.output;
}
