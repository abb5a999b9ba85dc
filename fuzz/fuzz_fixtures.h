#pragma once
// The small fixed inputs that some fuzz targets read their input against, and from which
// fuzz/make_seeds.cpp writes the seeds: a tiny scene with its images on disk, trainer and
// active-run options, a tiny synthetic dataset. All of it lives in fuzz::scratch().
#include <string>

#include "geometry/scene/scene.h"
#include "geometry/synth/synthetic_scene.h"
#include "nbv/active_run.h"
#include "splat/train/trainer.h"

namespace saresgs::fuzz {

// The tiny scene: 6 views of 16x12 px on a circle about the origin (PNG files under
// scratch()/tiny_scene/images), 8 coloured sparse points; view 0 is the test view.
const Scene& tinyScene();
// SH degree 1, the rest as 3DGS: the checkpoint of an 8-Gaussian model is about 2 KB.
TrainerOptions tinyTrainer();
// Random selection from 2 initial views to 4, 1 iteration per view held, no final fit.
ActiveOptions tinyActive();

// An `object` scene of 4 views at 16x12 and its dataset as `saresgs scene` writes it
// (at most 6 simulated points), written once to scratch()/tiny_dataset.
SyntheticOptions tinySyntheticOptions();
const std::string& tinyDataset();

}  // namespace saresgs::fuzz
