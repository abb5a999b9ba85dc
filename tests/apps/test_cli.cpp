// Runs the real `saresgs` binary as a user would: exit codes, messages, outputs.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <sstream>

#include "common/run_command.h"
#include "common/test_support.h"
#include "geometry/scene/scene.h"
#include "nbv/method.h"

using saresgs::test::runCli;
using saresgs::test::TempDir;
namespace fs = std::filesystem;

namespace {

using Result = saresgs::test::CommandResult;

}  // namespace

TEST(Cli, SceneWritesADatasetThatInfoReads) {
  TempDir d;
  const Result r = runCli("scene --layout room360 --views 16 --width 64 --height 48 --out " + d.file("s"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("16 views"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(d.path() / "s" / "contact_sheet.png"));
  const Result i = runCli("info --dataset " + d.file("s"));
  ASSERT_EQ(i.code, 0) << i.output;
  EXPECT_NE(i.output.find("16 with ground-truth depth"), std::string::npos) << i.output;
  // The summary's numbers are the library's.
  const saresgs::Scene s = saresgs::loadDataset(d.file("s"));
  EXPECT_NE(i.output.find("points:  " + std::to_string(s.points.size())), std::string::npos) << i.output;
}

TEST(Cli, BadInputGivesAClearErrorAndNonZeroExit) {
  TempDir d;
  Result r = runCli("info --dataset " + d.file("missing"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.output.find(d.file("missing")), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("does not exist"), std::string::npos) << r.output;

  r = runCli("scene --layout nowhere --out " + d.file("x"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.output.find("--layout"), std::string::npos) << r.output;

  r = runCli("scene --layout object --mesh " + d.file("no_such.off") + " --out " + d.file("x"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.output.find("no_such.off"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(d.path() / "x"));  // nothing half-written in place

  r = runCli("");
  EXPECT_NE(r.code, 0);

  // An unknown subcommand is named, with the choices.
  r = runCli("nosuch");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.output.find("unknown subcommand 'nosuch'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("active"), std::string::npos) << r.output;

  // Values that used to be accepted silently (negative seeds wrapped to 2^64 - 1, a
  // negative Fisher damping, a negative view count read as the default) are refused by
  // option name, before any work.
  for (const auto& [args, option] : std::vector<std::pair<std::string, std::string>>{
           {"scene --layout object --views -5 --out " + d.file("v"), "--views"},
           {"scene --layout object --views 2000000000 --out " + d.file("v"), "--views"},
           {"scene --layout object --seed -1 --out " + d.file("v"), "--seed"},
           {"train --dataset " + d.file("missing") + " --seed -3 --out " + d.file("t"), "--seed"},
           {"train --dataset " + d.file("missing") + " --max-gaussians -1 --out " + d.file("t"), "--max-gaussians"},
           {"active --dataset " + d.file("missing") + " --fisher-lambda -1 --out " + d.file("a"), "--fisher-lambda"},
           {"active --dataset " + d.file("missing") + " --max-views 0 --out " + d.file("a"), "--max-views"},
           {"active --dataset " + d.file("missing") + " --seed 12abc --out " + d.file("a"), "--seed"}}) {
    r = runCli(args);
    EXPECT_NE(r.code, 0) << args;
    EXPECT_NE(r.output.find(option), std::string::npos) << args << ": " << r.output;
  }
  EXPECT_FALSE(fs::exists(d.path() / "v"));

  // A benchmark too large for the machine is refused up front, naming the limit.
  r = runCli("bench step --width 16384 --height 16384 --gaussians 100000000");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.output.find("--gaussians"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("half this machine's memory"), std::string::npos) << r.output;
}

// One small scene for the pipeline commands: train, its outputs read back by real
// consumers (our .ply reader, the JSON), then coverage and an active run on it.
TEST(Cli, TrainCoverageAndActiveOnASmallScene) {
  TempDir d;
  ASSERT_EQ(runCli("scene --layout object --views 12 --width 64 --height 48 --out " + d.file("s")).code, 0);

  Result r = runCli("train --dataset " + d.file("s") + " --iterations 60 --sh-degree 1 --out " + d.file("t"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("PSNR"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("[train]"), std::string::npos) << r.output;  // progress on stderr
  const std::string results = saresgs::test::readBytes(d.file("t/results.json"));
  EXPECT_NE(results.find("\"psnr\""), std::string::npos);
  EXPECT_NE(results.find("\"ssim\""), std::string::npos);
  EXPECT_TRUE(fs::exists(d.path() / "t" / "test_renders" / "all.png"));
  ASSERT_TRUE(fs::exists(d.path() / "t" / "point_cloud.ply"));

  r = runCli("coverage --dataset " + d.file("s") +
             " --views 0,3 --set visible --encoding exact --score new --resolution 32 --out " + d.file("c"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("observed"), std::string::npos) << r.output;
  for (const char* f : {"coverage.json", "coverage.csv", "coverage.png"})
    EXPECT_TRUE(fs::exists(d.path() / "c" / f)) << f;
  // The trained model renders the extrapolated views just as well (datasets without truth).
  r = runCli("coverage --dataset " + d.file("s") + " --views 0,3 --model " + d.file("t/point_cloud.ply") +
             " --resolution 32 --out " + d.file("c2"));
  ASSERT_EQ(r.code, 0) << r.output;

  r = runCli("active --dataset " + d.file("s") +
             " --method fvs --max-views 5 --interval 4 --min-iterations 40 --final-iterations 0 --out " + d.file("a"));
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string ar = saresgs::test::readBytes(d.file("a/results.json"));
  for (const char* key : {"\"psnr\"", "\"ssim\"", "\"ause\"", "\"selected_views\"", "\"seconds\""})
    EXPECT_NE(ar.find(key), std::string::npos) << key;
  EXPECT_TRUE(fs::exists(d.path() / "a" / "cameras.png"));
  // Resident memory: the peak, and at the start of every phase, views never decreasing.
  {
    const auto mem = nlohmann::json::parse(ar).at("memory");
    EXPECT_GT(mem.at("peak_rss_bytes").get<double>(), 1e6);
    const auto& phases = mem.at("rss_at_phase_start_this_process");
    ASSERT_GE(phases.size(), 3u) << mem.dump();  // training phases, the final evaluation, the end
    int views = 0;
    for (const auto& p : phases) {
      EXPECT_GE(p.at("views").get<int>(), views) << mem.dump();
      views = p.at("views").get<int>();
      EXPECT_GT(p.at("rss_bytes").get<double>(), 1e6) << mem.dump();
      // The same unit as the peak (statm and getrusage count a little apart).
      EXPECT_LE(p.at("rss_bytes").get<double>(), 1.05 * mem.at("peak_rss_bytes").get<double>()) << mem.dump();
    }
    EXPECT_EQ(phases.back().at("phase"), "end");
    EXPECT_EQ(views, 5);
  }
  EXPECT_NE(r.output.find("peak resident memory"), std::string::npos) << r.output;
  // Running again into the same folder without --resume is refused (nothing overwritten).
  r = runCli("active --dataset " + d.file("s") +
             " --method fvs --max-views 5 --interval 4 --min-iterations 40 --final-iterations 0 --out " + d.file("a"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.output.find("--resume"), std::string::npos) << r.output;

  r = runCli("coverage --dataset " + d.file("s") + " --views 0,99 --out " + d.file("c3"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.output.find("--views"), std::string::npos) << r.output;
}

// Adding a method means adding it to nbv/method_table.cpp's table: the command line takes every
// method of allMethods() (the run then stops at the missing dataset, after the method was
// accepted) and refuses a name that is not one, listing the choices.
TEST(Cli, ActiveAcceptsEveryMethodOfTheList) {
  TempDir d;
  for (saresgs::Method m : saresgs::allMethods()) {
    const std::string name = saresgs::toString(m);
    const Result r = runCli("active --method " + name + " --dataset " + d.file("missing") + " --out " + d.file("o"));
    EXPECT_NE(r.code, 0) << name;
    EXPECT_NE(r.output.find(d.file("missing")), std::string::npos) << name << ": " << r.output;
    EXPECT_EQ(r.output.find("--method"), std::string::npos) << name << ": " << r.output;
  }
  const Result bad = runCli("active --method clairvoyant --dataset " + d.file("missing") + " --out " + d.file("o"));
  EXPECT_NE(bad.code, 0);
  EXPECT_NE(bad.output.find("--method"), std::string::npos) << bad.output;
  const Result help = runCli("active --help");
  EXPECT_NE(help.output.find(saresgs::methodChoices()), std::string::npos) << help.output;
}

// The final fit judges the chosen views apart from the loop's schedule: it is the method's
// own training from the initial model on exactly those views (residual supervision for
// sa-resgs), so `saresgs train --residual` on the same views with the final fit's options
// (quick preset: 3DGS's schedule, the cap, SH degree 0, the seed) gives the same model,
// byte for byte, and the same test PSNR; the plain refit of the same views is `saresgs
// train` without --residual, byte for byte too.
TEST(Cli, FinalFitEqualsTrainOnTheChosenViews) {
  TempDir d;
  ASSERT_EQ(runCli("scene --layout object --views 12 --width 64 --height 48 --out " + d.file("s")).code, 0);
  // One short active run of `method` (and `flags`) into OUT, and `saresgs train` on exactly
  // a run's views (initial, then selected) with its final fit's options.
  auto active = [&](const std::string& method, const std::string& flags, const std::string& out) {
    return runCli("active --dataset " + d.file("s") + " --method " + method +
                  " --max-views 5 --interval 4 --min-iterations 40 --final-iterations 150 --seed 3 --threads 2 " +
                  flags + "--out " + d.file(out));
  };
  auto trainOn = [&](const nlohmann::json& of_run) {
    std::string views;
    for (const auto& v : of_run["initial_views"]) views += (views.empty() ? "" : ",") + v.get<std::string>();
    for (const auto& v : of_run["selected_views"]) views += "," + v.get<std::string>();
    return "train --dataset " + d.file("s") + " --views " + views +
           " --iterations 150 --max-gaussians 40000 --sh-degree 0 --seed 3 --threads 2 ";
  };
  Result r = active("sa-resgs", "", "a");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("final fit on these views (150 it, residual)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("plain refit of these views (150 it)"), std::string::npos) << r.output;
  const nlohmann::json a = nlohmann::json::parse(saresgs::test::readBytes(d.file("a/results.json")));
  ASSERT_TRUE(a.contains("final_fit") && a.contains("final_fit_views")) << a.dump();
  EXPECT_EQ(a["final_fit"]["iterations"], 150);
  EXPECT_EQ(a["final_fit"]["residual"], true);
  EXPECT_EQ(a["final_fit_views"]["residual"], false);
  const std::string train = trainOn(a);
  for (const bool residual : {true, false}) {
    const std::string out = d.file(residual ? "tr" : "tp");
    r = runCli(train + (residual ? "--residual " : "") + "--out " + out);
    ASSERT_EQ(r.code, 0) << r.output;
    const nlohmann::json t = nlohmann::json::parse(saresgs::test::readBytes(out + "/results.json"));
    const nlohmann::json& fit = a[residual ? "final_fit" : "final_fit_views"];
    EXPECT_EQ(t["psnr"].get<double>(), fit["psnr"].get<double>()) << residual;
    EXPECT_EQ(t["ssim"].get<double>(), fit["ssim"].get<double>()) << residual;
    EXPECT_EQ(saresgs::test::readBytes(out + "/point_cloud.ply"),
              saresgs::test::readBytes(d.file(residual ? "a/final_fit.ply" : "a/final_fit_views.ply")))
        << residual;
  }
  // The two trainings differ (otherwise the comparison above would not tell them apart).
  EXPECT_NE(a["final_fit"]["psnr"].get<double>(), a["final_fit_views"]["psnr"].get<double>());
  // A method that trains plainly makes one fit, reported as both.
  r = active("fisher", "", "f");
  ASSERT_EQ(r.code, 0) << r.output;
  const nlohmann::json f = nlohmann::json::parse(saresgs::test::readBytes(d.file("f/results.json")));
  EXPECT_EQ(f["final_fit"]["residual"], false);
  EXPECT_EQ(f["final_fit_views"], f["final_fit"]);
  EXPECT_FALSE(std::filesystem::exists(d.file("f/final_fit_views.ply")));
  // --final-residual gives a plain-training method the residual final fit: the same views,
  // a final fit equal to `train --residual` on them, and the plain run's fit as the refit.
  r = active("fisher", "--final-residual ", "fr");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("final fit on these views (150 it, residual)"), std::string::npos) << r.output;
  const nlohmann::json fr = nlohmann::json::parse(saresgs::test::readBytes(d.file("fr/results.json")));
  EXPECT_EQ(fr["selected_views"], f["selected_views"]);
  EXPECT_EQ(fr["psnr"], f["psnr"]);
  EXPECT_EQ(fr["final_fit"]["residual"], true);
  EXPECT_EQ(fr["final_fit_views"], f["final_fit"]);
  r = runCli(trainOn(f) + "--residual --out " + d.file("ftr"));
  ASSERT_EQ(r.code, 0) << r.output;
  const nlohmann::json ftr = nlohmann::json::parse(saresgs::test::readBytes(d.file("ftr/results.json")));
  EXPECT_EQ(ftr["psnr"].get<double>(), fr["final_fit"]["psnr"].get<double>());
  EXPECT_EQ(saresgs::test::readBytes(d.file("ftr/point_cloud.ply")),
            saresgs::test::readBytes(d.file("fr/final_fit.ply")));
  EXPECT_NE(fr["final_fit"]["psnr"].get<double>(), f["final_fit"]["psnr"].get<double>());
  // --no-plain-refit leaves the plain refit out (results.json, the table, the .ply) and
  // changes nothing else: the same views and the same final fit.
  r = active("sa-resgs", "--no-plain-refit ", "n");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(r.output.find("plain refit"), std::string::npos) << r.output;
  const nlohmann::json n = nlohmann::json::parse(saresgs::test::readBytes(d.file("n/results.json")));
  EXPECT_FALSE(n.contains("final_fit_views")) << n.dump();
  EXPECT_EQ(n["selected_views"], a["selected_views"]);
  EXPECT_EQ(n["final_fit"], a["final_fit"]);
  EXPECT_EQ(saresgs::test::readBytes(d.file("n/final_fit.ply")), saresgs::test::readBytes(d.file("a/final_fit.ply")));
  EXPECT_FALSE(std::filesystem::exists(d.file("n/final_fit_views.ply")));
  // A view listed twice, or not a train view, is refused by name.
  r = runCli("train --dataset " + d.file("s") + " --views 0,0 --iterations 5 --out " + d.file("t2"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.output.find("--views"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("twice"), std::string::npos) << r.output;
}

// Intrinsics typed in the wrong unit: a focal length of 0.001 px (every point squeezed
// onto the principal point) is warned about by view and field; a principal point at
// (5000, -3000) for a 64x48 image leaves every view blind to the model's points, and the
// commands refuse it, naming the cameras and the first view's field.
TEST(Cli, ImplausibleIntrinsicsAreWarnedAboutOrRefusedByField) {
  TempDir d;
  Result r = runCli("scene --layout room360 --views 16 --width 64 --height 48 --out " + d.file("s"));
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string cams = d.file("s/sparse/0/cameras.txt"), original = saresgs::test::readBytes(cams);
  auto edit = [&](const std::string& f, const std::string& cx, const std::string& cy) {
    std::istringstream in(original);
    std::string out;
    for (std::string line; std::getline(in, line);) {
      if (!line.empty() && line[0] != '#') {
        // SIMPLE_PINHOLE: f cx cy; PINHOLE: fx fy cx cy.
        std::istringstream fields(line);
        std::string id, model, w, h, fx, fy, x, y;
        fields >> id >> model >> w >> h >> fx;
        if (model == "PINHOLE") fields >> fy;
        fields >> x >> y;
        line = id + " " + model + " " + w + " " + h + " " + (f.empty() ? fx : f) +
               (model == "PINHOLE" ? " " + (f.empty() ? fy : f) : std::string()) + " " + (cx.empty() ? x : cx) + " " +
               (cy.empty() ? y : cy);
      }
      out += line + "\n";
    }
    saresgs::test::writeBytes(cams, out);
  };
  edit("0.001", "", "");
  r = runCli("info --dataset " + d.file("s"));
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("warning: 0001.png: fx: fx = 0.001 px"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("more like these"), std::string::npos) << r.output;
  edit("", "5000", "-3000");
  r = runCli("info --dataset " + d.file("s"));
  EXPECT_NE(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("intrinsics or poses"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("cx = 5000"), std::string::npos) << r.output;
}
