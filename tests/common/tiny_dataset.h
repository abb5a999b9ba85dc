#pragma once
// A small synthetic dataset (written once per test program into a temporary folder)
// for the trainer tests: the object layout at 64x48, 16 views, ~1500 SfM points.
#include <memory>

#include "geometry/scene/scene.h"
#include "geometry/synth/synthetic_scene.h"
#include "geometry/synth/write_dataset.h"
#include "common/synthetic_options.h"
#include "common/test_support.h"

namespace saresgs::test {

// The options the tiny dataset is made with (tests rebuild the scene for ground truth).
inline SyntheticOptions tinyDatasetOptions() {
  return syntheticOptions("object", 64, 48, /*seed=*/3, /*num_views=*/16);
}

// The folder it is written to (once per test program).
inline const std::string& tinyDatasetPath() {
  static std::unique_ptr<TempDir> dir;
  static std::string path;
  if (!dir) {
    dir = std::make_unique<TempDir>();
    WriteDatasetOptions w;
    w.simulated.max_points = 1500;
    w.simulated.candidates = 6000;
    w.simulated.seed = 3;
    writeSyntheticDataset(makeSyntheticScene(tinyDatasetOptions()), dir->file("ds"), w);
    path = dir->file("ds");
  }
  return path;
}

inline const Scene& tinyDataset() {
  static const Scene scene = loadDataset(tinyDatasetPath());
  return scene;
}

}  // namespace saresgs::test
