#include "fuzz/fuzz_fixtures.h"

#include <cmath>
#include <filesystem>

#include "fuzz/fuzz_support.h"
#include "geometry/image/image.h"
#include "geometry/synth/write_dataset.h"
#include "tests/common/ring_run.h"
#include "tests/common/ring_scene.h"
#include "tests/common/synthetic_options.h"

namespace saresgs::fuzz {

namespace fs = std::filesystem;

const Scene& tinyScene() {
  static const Scene scene = [] {
    // The tests' ring scene, whose checkpoints seed the fuzz targets, with images on disk.
    Scene s = test::ringScene([](int i) { return "view" + std::to_string(i) + ".png"; }, true);
    const std::string dir = scratchPath("tiny_scene/images/x");
    s.source = fs::path(dir).parent_path().parent_path().string();
    for (std::size_t i = 0; i < s.views.size(); ++i) {
      SceneView& v = s.views[i];
      v.image_path = (fs::path(dir).parent_path() / v.name).string();
      Image8 img(v.camera.K.width, v.camera.K.height, 3);
      for (std::size_t p = 0; p < img.data.size(); ++p)
        img.data[p] = static_cast<std::uint8_t>((p * 37 + i * 11) % 251);
      writeImage(v.image_path, img);
    }
    for (int p = 0; p < 8; ++p) {
      SparsePoint sp;
      sp.xyz = Eigen::Vector3d((p & 1) - 0.5, ((p >> 1) & 1) - 0.5, ((p >> 2) & 1) - 0.5);
      sp.rgb = {static_cast<std::uint8_t>(40 * p), 128, static_cast<std::uint8_t>(255 - 30 * p)};
      s.points.push_back(sp);
    }
    s.finalize();
    return s;
  }();
  return scene;
}

TrainerOptions tinyTrainer() {
  TrainerOptions o;
  o.max_sh_degree = 1;
  o.seed = 7;
  return o;
}

ActiveOptions tinyActive() {
  // The run whose checkpoints the tests replay, with no progress or final evaluation.
  ActiveOptions o = test::ringRunOptions();
  o.progress_test_views = 0;
  o.final_iterations = 0;
  o.trainer = tinyTrainer();
  return o;
}

SyntheticOptions tinySyntheticOptions() {
  return test::syntheticOptions("object", 16, 12, /*seed=*/1, /*num_views=*/4);
}

const std::string& tinyDataset() {
  static const std::string dir = [] {
    const std::string d = scratchPath("tiny_dataset");
    WriteDatasetOptions w;
    w.simulated.max_points = 6;
    w.simulated.candidates = 400;
    w.simulated.seed = 1;
    writeSyntheticDataset(makeSyntheticScene(tinySyntheticOptions()), d, w);
    return d;
  }();
  return dir;
}

}  // namespace saresgs::fuzz
