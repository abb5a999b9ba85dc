// Bad input through the real binary (issue 15, section 2): each class of malformed input
// exits non-zero within a bounded time, names the file or option and the field, and never
// shows a library's own words ("type must be", "cannot use value()", "stoi",
// "_M_range_check").
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <functional>

#include "common/run_command.h"
#include "common/test_support.h"

using saresgs::test::readBytes;
using saresgs::test::TempDir;
using saresgs::test::writeBytes;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

using Result = saresgs::test::CommandResult;

// At most 60 s: a refusal is up front, so a timeout (exit 124) is a hang.
Result run(const std::string& args) {
  return saresgs::test::runCommand("timeout 60 " + std::string(SARESGS_CLI) + " " + args);
}

void expectRefused(const Result& r, const std::vector<std::string>& names, const std::string& what) {
  EXPECT_NE(r.code, 0) << what << ": " << r.output;
  EXPECT_NE(r.code, 124) << what << ": timed out";
  for (const std::string& n : names)
    EXPECT_NE(r.output.find(n), std::string::npos) << what << ": no '" << n << "' in " << r.output;
  for (const char* raw : {"type must be", "cannot use value()", "json.exception", "stoi", "stoll", "_M_range_check"})
    EXPECT_EQ(r.output.find(raw), std::string::npos) << what << ": " << r.output;
}

json readJson(const std::string& path) { return json::parse(readBytes(path)); }
void writeJson(const std::string& path, const json& j) { writeBytes(path, j.dump(2)); }

// A copy of `src` as `dst` with `edit` applied to the JSON file `file` in it.
std::string edited(const TempDir& d, const std::string& src, const std::string& dst, const std::string& file,
                   const std::function<void(json&)>& edit) {
  fs::copy(d.file(src), d.file(dst), fs::copy_options::recursive);
  json j = readJson(d.file(dst + "/" + file));
  edit(j);
  writeJson(d.file(dst + "/" + file), j);
  return d.file(dst);
}

}  // namespace

TEST(CliInputs, MalformedDatasetFilesNameTheFileAndField) {
  TempDir d;
  ASSERT_EQ(run("scene --layout object --views 12 --width 64 --height 48 --out " + d.file("s")).code, 0);
  ASSERT_EQ(
      run("scene --layout object --views 12 --width 64 --height 48 --format blender --no-points --out " + d.file("b"))
          .code,
      0);

  // Wrong JSON types (manifest, transforms).
  std::string ds = edited(d, "s", "m1", "manifest.json", [](json& j) { j["split"] = json::array({1, 2}); });
  expectRefused(run("info --dataset " + ds), {"manifest.json", "split"}, "split as an array");
  ds = edited(d, "s", "m2", "manifest.json", [](json& j) { j["width"] = "abc"; });
  expectRefused(run("info --dataset " + ds), {"manifest.json", "width"}, "width as a string");
  ds = edited(d, "b", "b1", "transforms_train.json", [](json& j) { j["camera_angle_x"] = "wide"; });
  expectRefused(run("info --dataset " + ds), {"transforms_train.json", "camera_angle_x"}, "camera_angle_x as a string");
  ds = edited(d, "b", "b2", "transforms_test.json", [](json& j) { j["frames"][0]["transform_matrix"][0] = "row"; });
  expectRefused(run("info --dataset " + ds), {"transforms_test.json", "frames[0].transform_matrix[0]"},
                "a matrix row as a string");

  // Unbounded sizes: refused up front, with the limit.
  ds = edited(d, "s", "m3", "manifest.json", [](json& j) { j["num_views"] = 2e9; });
  expectRefused(run("coverage --dataset " + ds + " --views 0,1 --out " + d.file("c")),
                {"manifest.json", "num_views", "100000"}, "num_views 2e9");
  ds = edited(d, "s", "m4", "manifest.json", [](json& j) { j["height"] = 1e9; });
  expectRefused(run("info --dataset " + ds), {"manifest.json", "height", "65536"}, "height 1e9");

  // Silent acceptance: a size or count that disagrees with the cameras, a split name twice
  // or in both parts, an image listed twice in a Blender split, a width that would wrap.
  ds = edited(d, "s", "m5", "manifest.json", [](json& j) { j["width"] = 128; });
  expectRefused(run("info --dataset " + ds), {"manifest.json", "width", "64 wide"},
                "manifest width 128 for 64-wide cameras");
  ds = edited(d, "s", "m6", "manifest.json", [](json& j) { j["num_views"] = 11; });
  expectRefused(run("info --dataset " + ds), {"manifest.json", "num_views", "12 views"}, "num_views 11 for 12 views");
  ds = edited(d, "s", "m7", "manifest.json", [](json& j) { j["split"]["test"].push_back(j["split"]["train"][0]); });
  expectRefused(run("info --dataset " + ds), {"manifest.json", "split.test", "twice"}, "a train image in test");
  ds = edited(d, "b", "b3", "transforms_train.json", [](json& j) { j["frames"].push_back(j["frames"][0]); });
  expectRefused(run("info --dataset " + ds), {"transforms_train.json", "file_path", "listed twice"}, "a frame twice");
  fs::copy(d.file("s"), d.file("w"), fs::copy_options::recursive);
  std::string cams = readBytes(d.file("w/sparse/0/cameras.txt"));
  const auto at = cams.find(" 64 48 ");
  ASSERT_NE(at, std::string::npos) << cams;
  cams.replace(at, 7, " 4294967360 48 ");  // 2^32 + 64
  writeBytes(d.file("w/sparse/0/cameras.txt"), cams);
  expectRefused(run("info --dataset " + d.file("w")), {"cameras.txt", "width", "65536"}, "width 2^32 + 64");
}

TEST(CliInputs, OptionsAndCheckpointsNameTheOptionOrFieldAndTheRenamedIterationsSaysSo) {
  TempDir d;
  ASSERT_EQ(run("scene --layout object --views 12 --width 64 --height 48 --out " + d.file("s")).code, 0);
  const std::string s = d.file("s");
  // Negative or malformed counts are refused by option, not replaced by defaults.
  for (const auto& [args, option] : std::vector<std::pair<std::string, std::string>>{
           {"train --dataset " + s + " --iterations -5 --out " + d.file("t"), "--iterations"},
           {"train --dataset " + s + " --checkpoint-every -1 --out " + d.file("t"), "--checkpoint-every"},
           {"active --dataset " + s + " --max-views -2 --out " + d.file("a"), "--max-views"},
           {"active --dataset " + s + " --interval -1 --out " + d.file("a"), "--interval"},
           {"active --dataset " + s + " --min-iterations -300 --out " + d.file("a"), "--min-iterations"},
           {"active --dataset " + s + " --seed -1 --out " + d.file("a"), "--seed"},
           {"active --dataset " + s + " --final-iterations -1 --out " + d.file("a"), "--final-iterations"},
           {"scene --layout object --views -1 --out " + d.file("v"), "--views"},
           {"train --dataset " + s + " --views 99999999999999999999 --iterations 5 --out " + d.file("t"), "--views"},
           {"train --dataset " + s + " --views 0,x --iterations 5 --out " + d.file("t"), "--views"},
           {"train --dataset " + s + " --views , --iterations 5 --out " + d.file("t"), "--views"},
           {"coverage --dataset " + s + " --views -1 --out " + d.file("c"), "--views"},
       })
    expectRefused(run(args), {option}, args);
  EXPECT_FALSE(fs::exists(d.path() / "t" / "results.json"));

  // The loop's least total was called --iterations, which read as an exact count.
  expectRefused(run("active --dataset " + s + " --iterations 300 --out " + d.file("a")),
                {"--iterations", "--min-iterations"}, "--iterations");

  // A corrupt active checkpoint: each field by name.
  Result r =
      run("active --dataset " + s +
          " --method random --max-views 6 --interval 3 --min-iterations 10 --final-iterations 0 --out " + d.file("a"));
  ASSERT_EQ(r.code, 0) << r.output;
  const json results = readJson(d.file("a/results.json"));
  EXPECT_EQ(results["options"]["total_iterations"], 10);
  EXPECT_EQ(results["phase_iterations"], json::array({12, 15, 18}));  // 4, 5, 6 views x 3: more than 10
  EXPECT_EQ(results["iterations"], 45);
  EXPECT_NE(r.output.find("45 iterations in the loop (12 + 15 + 18; at least 10 asked)"), std::string::npos)
      << r.output;
  const json good = readJson(d.file("a/checkpoint.json"));
  for (const auto& [edit, field] : std::vector<std::pair<std::function<void(json&)>, std::string>>{
           {[](json& j) { j["selected"][2] = "7"; }, "selected[2]"},
           {[](json& j) { j["selected"] = 3; }, "selected"},
           {[](json& j) { j["selected"][4] = 1e15; }, "selected[4]"},
           {[](json& j) { j["iterations_done"] = -1e9; }, "iterations_done"},
           {[](json& j) { j["steps"][0]["scores"][0] = "high"; }, "steps[0].scores[0]"},
       }) {
    json j = good;
    edit(j);
    writeJson(d.file("a/checkpoint.json"), j);
    expectRefused(run("active --dataset " + s +
                      " --method random --max-views 6 --interval 3 --min-iterations 10 --final-iterations 0 "
                      "--resume --out " +
                      d.file("a")),
                  {d.file("a/checkpoint.json"), field}, field);
  }
}

// The memory budget (issue 25): a run whose images and initial model do not fit is refused
// before it starts, naming --memory-budget with the estimate and what to change; one that
// fits has its model capped to the budget, and densification honours the cap.
TEST(CliInputs, MemoryBudgetRefusesEarlyOrCapsTheModel) {
  saresgs::test::TempDir d;
  const std::string data = d.file("tiny");
  Result r = run("scene --layout object --views 12 --width 64 --height 48 --out " + data);
  ASSERT_EQ(r.code, 0) << r.output;
  r = run("train --dataset " + data + " --iterations 5 --out " + d.file("o1") + " --memory-budget 0.001");
  EXPECT_NE(r.code, 0);
  for (const char* says : {"--memory-budget", "needs about", "images", "initial model", "--downscale"})
    EXPECT_NE(r.output.find(says), std::string::npos) << says << ": " << r.output;
  EXPECT_FALSE(std::filesystem::exists(d.file("o1") + "/results.json"));
  r = run("active --dataset " + data + " --out " + d.file("o2") + " --memory-budget 0.001");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.output.find("--memory-budget"), std::string::npos) << r.output;

  // A budget with room for about 1.5x the initial 12k Gaussians: the run states the cap
  // and trains with it (results.json), and the estimate at the end is within the budget.
  r = run("train --dataset " + data + " --iterations 20 --out " + d.file("o3") + " --memory-budget 0.1");
  ASSERT_EQ(r.code, 0) << r.output;
  const std::size_t at = r.output.find("capped at ");
  ASSERT_NE(at, std::string::npos) << r.output;
  const std::size_t cap = std::stoull(r.output.substr(at + 10));
  EXPECT_GT(cap, 12000u);
  EXPECT_LT(cap, 40000u);
  const nlohmann::json j = nlohmann::json::parse(saresgs::test::readBytes(d.file("o3") + "/results.json"));
  EXPECT_EQ(j["max_gaussians"].get<std::size_t>(), cap);
  EXPECT_LE(j["gaussians"].get<std::size_t>(), cap);
  EXPECT_LE(j["memory"]["estimate_at_end_bytes"].get<double>(), 1e8);
  EXPECT_EQ(j["memory"]["budget_from"], "--memory-budget");
  // Without a budget nothing is capped: the numbers do not depend on what is free.
  r = run("train --dataset " + data + " --iterations 20 --out " + d.file("o4"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(nlohmann::json::parse(saresgs::test::readBytes(d.file("o4") + "/results.json"))["max_gaussians"], 0);
}
