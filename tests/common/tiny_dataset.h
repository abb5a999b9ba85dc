#pragma once
// A small synthetic dataset (written once per test program into a temporary folder)
// for the trainer tests: the object layout at 64x48, 16 views, ~1500 SfM points.
#include <memory>

#include "geometry/scene/scene.h"
#include "geometry/synth/synthetic_scene.h"
#include "geometry/synth/write_dataset.h"
#include "common/test_support.h"

namespace saresgs::test {

// The options the tiny dataset is made with (tests rebuild the scene for ground truth).
inline SyntheticOptions tinyDatasetOptions() {
  SyntheticOptions o;
  o.layout = "object";
  o.width = 64;
  o.height = 48;
  o.num_views = 16;
  o.seed = 3;
  return o;
}

inline const Scene& tinyDataset() {
  static std::unique_ptr<TempDir> dir;
  static Scene scene;
  if (!dir) {
    dir = std::make_unique<TempDir>();
    const SyntheticOptions o = tinyDatasetOptions();
    WriteDatasetOptions w;
    w.simulated.max_points = 1500;
    w.simulated.candidates = 6000;
    w.simulated.seed = 3;
    writeSyntheticDataset(makeSyntheticScene(o), dir->file("ds"), w);
    scene = loadDataset(dir->file("ds"));
  }
  return scene;
}

}  // namespace saresgs::test
