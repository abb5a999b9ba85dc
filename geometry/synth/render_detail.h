#pragma once
// Rendering internals, visible to tests: the public SyntheticScene::render raises the
// sample count to at least 4 and rounds it up to a square grid; these functions take
// the grid as given.
#include "geometry/camera/camera.h"
#include "geometry/image/image.h"

namespace saresgs {
class SyntheticScene;  // geometry/synth/synthetic_scene.h
}

namespace saresgs::synth {

// Renders with grid x grid samples per pixel. With `jitter`, each sample sits at a
// deterministic pseudo-random position inside its cell (a hash of pixel and sample);
// without, at the cell centre (grid 1 without jitter: one ray through the pixel centre).
// With `alpha`, the image has a fourth channel, the fraction of samples that hit a
// surface, and its colour is the mean of the hits alone (straight alpha; black where
// nothing is hit): composited on the background it is the RGB render.
ImageF renderGrid(const SyntheticScene& scene, const Camera& cam, int grid, bool jitter, bool specular,
                  bool alpha = false);

// The grid size that the public render uses for a requested sample count.
int gridForSamples(int samples_per_pixel);

}  // namespace saresgs::synth
