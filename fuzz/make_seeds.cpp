// Writes the seed corpus of every fuzz target (fuzz/corpus/<target>/) with the project's
// own writers, from the fixtures of fuzz_support.h, so that each seed is a valid file of
// the kind the target reads:
//   saresgs_fuzz_seeds OUT_DIR RESULTS_DIR   (RESULTS_DIR: the repository's results/)
// The ablation seeds are the committed grid configs of results/. The Blender seeds are
// the tiny scene's cameras in NeRF-synthetic and Instant-NGP form (saresgs has no Blender
// writer). Run it after a format changes; the test command checks that every seed reads.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "fuzz/fuzz_fixtures.h"
#include "fuzz/fuzz_support.h"
#include "geometry/io/colmap.h"
#include "geometry/io/pfm.h"
#include "geometry/io/point_ply.h"
#include "geometry/lifting/correspondence.h"
#include "geometry/synth/simulated_sfm.h"
#include "geometry/synth/write_dataset.h"
#include "nbv/active_run.h"
#include "splat/ply.h"
#include "splat/train/init.h"
#include "splat/train/trainer.h"

namespace {

namespace fs = std::filesystem;
using namespace saresgs;

void seed(const fs::path& out, const std::string& target, const std::string& name, const std::string& bytes) {
  fs::create_directories(out / target);
  fuzz::writeBytes((out / target / name).string(), bytes);
  std::printf("%s/%s: %zu bytes\n", target.c_str(), name.c_str(), bytes.size());
}

// The three files of a model written by `write` into a scratch folder, as one input.
template <typename Write>
std::string packedModel(const ColmapModel& m, const std::string& ext, Write write) {
  const std::string dir = fuzz::scratchPath("seeds/model_" + ext + "/x");
  write(fs::path(dir).parent_path().string(), m);
  std::vector<std::string> files;
  for (const char* stem : {"cameras", "images", "points3D"})
    files.push_back(fuzz::readBytes((fs::path(dir).parent_path() / (std::string(stem) + ext)).string()));
  return fuzz::joinFiles(files);
}

// A model with both pinhole models and a few observed points: the tiny dataset's (one
// camera model) plus a PINHOLE camera for its last image.
ColmapModel tinyModel() {
  const SyntheticScene scene = makeSyntheticScene(fuzz::tinySyntheticOptions());
  ColmapModel m = colmapModelOf(scene);
  SimulatedSfmOptions o;
  o.max_points = 4;
  o.candidates = 400;
  o.seed = 2;
  simulateSfm(scene, m, o);
  ColmapCamera c = m.cameras.begin()->second;
  c.id = 2;
  c.model = "PINHOLE";
  c.params = {c.params[0], c.params[0] * 1.01, c.params[1], c.params[2]};
  m.cameras[2] = c;
  m.images.rbegin()->second.camera_id = 2;
  return m;
}

// transforms_*.json for the tiny scene's views (OpenGL camera-to-world poses).
nlohmann::json transforms(const std::vector<int>& views, bool instant_ngp) {
  const Scene& s = fuzz::tinyScene();
  nlohmann::json j;
  const Intrinsics& K = s.views[0].camera.K;
  if (instant_ngp) {
    j["fl_x"] = K.fx;
    j["fl_y"] = K.fy;
    j["cx"] = K.cx;
    j["cy"] = K.cy;
    j["w"] = 8;
    j["h"] = 6;
  } else {
    j["camera_angle_x"] = 2 * std::atan(0.5 * K.width / K.fx);
  }
  j["frames"] = nlohmann::json::array();
  for (int v : views) {
    const Camera& c = s.views[static_cast<std::size_t>(v)].camera;
    Eigen::Matrix4d c2w = Eigen::Matrix4d::Identity();
    c2w.topLeftCorner<3, 3>() = c.R.transpose() * Eigen::Vector3d(1, -1, -1).asDiagonal();
    c2w.topRightCorner<3, 1>() = c.center();
    nlohmann::json m = nlohmann::json::array();
    for (int r = 0; r < 4; ++r) m.push_back({c2w(r, 0), c2w(r, 1), c2w(r, 2), c2w(r, 3)});
    j["frames"].push_back({{"file_path", "./r_" + std::to_string(v % 4)}, {"transform_matrix", m}});
  }
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: saresgs_fuzz_seeds OUT_DIR RESULTS_DIR\n");
    return 2;
  }
  const fs::path out = argv[1], results = argv[2];

  const ColmapModel model = tinyModel();
  seed(out, "colmap_text", "tiny_model", packedModel(model, ".txt", writeColmapText));
  seed(out, "colmap_binary", "tiny_model", packedModel(model, ".bin", writeColmapBinary));

  seed(out, "blender", "nerf_train_test",
       fuzz::joinFiles({transforms({1, 2, 3}, false).dump(2), transforms({0}, false).dump(2)}));
  seed(out, "blender", "instant_ngp_train", transforms({1, 2, 3, 4}, true).dump(2));

  for (int degree : {0, 3}) {
    std::vector<ColoredPoint> pts;
    for (const SparsePoint& p : fuzz::tinyScene().points)
      pts.push_back({p.xyz, {p.rgb[0] / 255.0f, p.rgb[1] / 255.0f, p.rgb[2] / 255.0f}});
    pts.resize(3);
    const std::string path = fuzz::scratchPath("seeds/degree" + std::to_string(degree) + ".ply");
    writeGaussiansPly(path, gaussiansFromPoints(pts, degree, 0.1f));
    seed(out, "ply", "sh_degree" + std::to_string(degree), fuzz::readBytes(path));
  }

  {
    // 3DGS's points3d.ply as saresgs writes it (binary), and the ascii forms other tools
    // write: double coordinates without colours, and extra properties between the ones read.
    std::vector<PlyPoint> pts;
    for (const SparsePoint& p : fuzz::tinyScene().points) pts.push_back({p.xyz, {p.rgb[0], p.rgb[1], p.rgb[2]}});
    pts.resize(3);
    const std::string path = fuzz::scratchPath("seeds/points3d.ply");
    writePointsPly(path, pts);
    seed(out, "points_ply", "binary_3dgs", fuzz::readBytes(path));
    seed(out, "points_ply", "ascii_xyz_double",
         "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\nproperty double y\nproperty double z\n"
         "end_header\n0.5 -1.25 2\n1e-3 3.5 -0.75\n");
    seed(out, "points_ply", "ascii_extra_properties",
         "ply\nformat ascii 1.0\ncomment two faces follow\nelement vertex 2\nproperty float x\nproperty float y\n"
         "property float z\nproperty float confidence\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
         "element face 0\nproperty list uchar int vertex_indices\nend_header\n0 0 1 0.9 255 0 10\n0.25 0.5 1 0.1 3 200 "
         "99\n");
  }

  for (int channels : {1, 3}) {
    ImageF img(4, 3, channels);
    for (std::size_t p = 0; p < img.data.size(); ++p) img.data[p] = 0.25f * static_cast<float>(p % 7);
    const std::string path = fuzz::scratchPath("seeds/c" + std::to_string(channels) + ".pfm");
    writePfm(path, img);
    seed(out, "pfm", channels == 1 ? "depth_4x3" : "rgb_4x3", fuzz::readBytes(path));
  }

  {
    const std::vector<Correspondence> m = {
        {{0.5, 0.5}, {1.25, 0.75}}, {{12.5, 30.5}, {11.0, 29.5}}, {{63.5, 47.5}, {60.0, 44.0}}};
    const std::string path = fuzz::scratchPath("seeds/matches.txt");
    writeMatches(path, m);
    seed(out, "matches", "three", fuzz::readBytes(path));
  }

  seed(out, "manifest", "tiny_dataset", fuzz::readBytes(fuzz::tinyDataset() + "/manifest.json"));

  {
    Trainer t(fuzz::tinyScene(), fuzz::tinyTrainer());
    const std::string path = fuzz::scratchPath("seeds/trainer.bin");
    t.saveCheckpoint(path);
    seed(out, "trainer_checkpoint", "fresh", fuzz::readBytes(path));
    t.train(fuzz::tinyScene().train, 3);
    t.saveCheckpoint(path);
    seed(out, "trainer_checkpoint", "after_3_iterations", fuzz::readBytes(path));
  }

  {
    // A run stopped after its first selection leaves the checkpoint of 3 views held.
    struct Stop {};
    const std::string path = fuzz::scratchPath("seeds/active/checkpoint.json");
    ActiveOptions o = fuzz::tinyActive();
    o.max_views = 3;
    ActiveRun(fuzz::tinyScene(), o, path).run();
    seed(out, "active_checkpoint", "three_views", fuzz::readBytes(path));
  }

  for (const char* grid : {"grid_small.json", "grid_prefilter.json", "grid_verdict.json"})
    seed(out, "ablation_config", grid, fuzz::readBytes((results / grid).string()));
  return 0;
}
