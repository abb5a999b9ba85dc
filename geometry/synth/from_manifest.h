#pragma once
// Rebuilding the ground-truth scene behind a dataset written by `saresgs scene`, so that
// tools can render views that were never written (extrapolated cameras for SA-Points).
#include <optional>
#include <string>

#include "geometry/scene/scene.h"
#include "geometry/synth/synthetic_scene.h"

namespace saresgs {

// The options that made the dataset in `folder`, when its manifest.json says it is a
// synthetic scene built from procedural meshes and textures only (files given to
// `--mesh`/`--texture` are not recorded well enough to rebuild); nullopt otherwise.
// Throws InputError naming the field for a manifest that is not valid JSON, a value of
// the wrong type or out of range (num_views over kMaxSyntheticViews, ...).
std::optional<SyntheticOptions> syntheticOptionsFromManifest(const std::string& folder);

// makeSyntheticScene(options) checked against the dataset's cameras (same count, centres
// within 1e-6 of the extent); nullopt when the folder is not a rebuildable synthetic scene;
// InputError when its manifest declares another number of views than the dataset has.
std::optional<SyntheticScene> rebuildSyntheticScene(const std::string& folder, const Scene& dataset);

}  // namespace saresgs
