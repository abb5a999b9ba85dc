// nerfstudio's transforms.json as ns-process-data writes it, against the Blender folder
// of the same scene: same cameras, split and points, and the same trained PSNR.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "common/run_command.h"
#include "common/test_support.h"
#include "geometry/image/image.h"
#include "geometry/io/json_file.h"
#include "geometry/scene/scene.h"

using saresgs::test::runCli;
using saresgs::test::TempDir;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

double psnrOf(const std::string& results) { return saresgs::readJsonFile(results).at("psnr").get<double>(); }

// The Blender folder `blender` rewritten as nerfstudio's: one transforms.json with the
// intrinsics at the top level (and repeated in every other frame), camera_model OPENCV
// with zero distortion, JPEG images under images/, the points as sparse_pc.ply through
// ply_file_path, the split as train_filenames / test_filenames, an identity
// applied_transform.
void toNerfstudio(const std::string& blender, const std::string& out) {
  fs::create_directories(fs::path(out) / "images");
  json ns;
  ns["camera_model"] = "OPENCV";
  for (const char* k : {"k1", "k2", "p1", "p2"}) ns[k] = 0.0;
  ns["applied_transform"] =
      json::array({json::array({1, 0, 0, 0}), json::array({0, 1, 0, 0}), json::array({0, 0, 1, 0})});
  ns["ply_file_path"] = "sparse_pc.ply";
  ns["frames"] = json::array();
  const saresgs::Scene b = saresgs::loadDataset(blender);
  const saresgs::Intrinsics& K = b.views[0].camera.K;
  ns.update({{"fl_x", K.fx}, {"fl_y", K.fy}, {"cx", K.cx}, {"cy", K.cy}, {"w", K.width}, {"h", K.height}});
  int k = 0;
  for (const char* split : {"transforms_train.json", "transforms_test.json"}) {
    const json t = saresgs::readJsonFile((fs::path(blender) / split).string());
    for (const json& f : t["frames"]) {
      const std::string stem = fs::path(f["file_path"].get<std::string>()).stem().string();
      const std::string src = (fs::path(blender) / f["file_path"].get<std::string>()).lexically_normal().string();
      const saresgs::Image8 img = saresgs::readImage(fs::exists(src) ? src : src + ".png");
      saresgs::writeImage((fs::path(out) / "images" / (stem + ".jpg")).string(), img);
      json g = {{"file_path", "images/" + stem + ".jpg"}, {"transform_matrix", f["transform_matrix"]}};
      if (k++ % 2 == 1)  // per-frame intrinsics, as nerfstudio writes for several cameras
        for (const char* key : {"fl_x", "fl_y", "cx", "cy", "w", "h"}) g[key] = ns[key];
      ns["frames"].push_back(g);
      ns[std::string(split) == "transforms_train.json" ? "train_filenames" : "test_filenames"].push_back("images/" +
                                                                                                         stem + ".jpg");
    }
  }
  fs::copy_file(fs::path(blender) / "points3d.ply", fs::path(out) / "sparse_pc.ply");
  std::ofstream(fs::path(out) / "transforms.json") << ns.dump(2);
}

}  // namespace

TEST(NerfstudioCli, TransformsJsonTrainsAsTheBlenderFolderDoes) {
  TempDir d;
  auto r =
      runCli("scene --layout room360 --views 24 --width 96 --height 72 --format blender --out " + d.file("blender"));
  ASSERT_EQ(r.code, 0) << r.output;
  toNerfstudio(d.file("blender"), d.file("ns"));

  const saresgs::Scene b = saresgs::loadDataset(d.file("blender"));
  const saresgs::Scene n = saresgs::loadDataset(d.file("ns"));
  ASSERT_EQ(n.views.size(), b.views.size());
  ASSERT_EQ(n.train.size(), b.train.size());
  ASSERT_EQ(n.test.size(), b.test.size());
  for (std::size_t i = 0; i < b.views.size(); ++i) {
    EXPECT_EQ(fs::path(n.views[i].name).stem(), fs::path(b.views[i].name).stem());
    EXPECT_LT((n.views[i].camera.projectionMatrix() - b.views[i].camera.projectionMatrix()).norm(), 1e-9) << i;
  }
  EXPECT_EQ(n.train, b.train);
  EXPECT_EQ(n.test, b.test);
  ASSERT_EQ(n.points.size(), b.points.size());
  EXPECT_GT(n.points.size(), 100u);
  EXPECT_FALSE(n.background.has_value());  // opaque JPEGs, like the room's Blender folder
  EXPECT_FALSE(b.background.has_value());

  // Trained the same way, the two reach the same PSNR (JPEG's loss aside).
  for (const char* which : {"blender", "ns"}) {
    r = runCli("train --dataset " + d.file(which) + " --iterations 300 --seed 0 --threads 1 --out " +
               d.file(std::string("t_") + which));
    ASSERT_EQ(r.code, 0) << r.output;
  }
  // cameras.json beside the .ply: every view, named by its image.
  const json cams = saresgs::readJsonFile(d.file("t_ns/cameras.json"));
  ASSERT_EQ(cams.size(), n.views.size());
  EXPECT_EQ(cams[5]["img_name"], fs::path(n.views[5].name).stem().string());
  const double pb = psnrOf(d.file("t_blender/results.json")), pn = psnrOf(d.file("t_ns/results.json"));
  std::printf("trained PSNR: Blender folder %.3f dB, nerfstudio folder %.3f dB\n", pb, pn);
  EXPECT_GT(pb, 15.0);
  EXPECT_NEAR(pn, pb, 0.25) << "Blender " << pb << " dB, nerfstudio " << pn << " dB";
}
