#pragma once
// manifest.json of a dataset written by `saresgs scene` (geometry/synth/write_dataset.h),
// as the dataset loaders use it: the split by image name, the data's background and the
// image size and view count the cameras must agree with. Every field is checked for type
// and range when read; other fields (layout, light, objects, ...) are left to
// geometry/synth/from_manifest.h.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "geometry/camera/camera.h"

namespace saresgs {

// The most views `saresgs scene` writes, and so the most a manifest may declare.
inline constexpr int kMaxSyntheticViews = 100000;

struct DatasetManifest {
  std::string path;
  // "split": image names; no name twice, none in both.
  std::optional<std::vector<std::string>> train, test;
  // "background": absent (nothing said), null (the data has none) or 3 numbers.
  bool background_given = false;
  std::optional<std::array<float, 3>> background;
  std::optional<int> width, height, num_views;
};

// Throws InputError(path, field, ...) for a wrong type, a value out of range
// (num_views 1..kMaxSyntheticViews, sizes 1..kMaxImageSide) or a repeated split name.
DatasetManifest readDatasetManifest(const std::string& path);

// The dataset's views against the manifest: their count and each camera's full-resolution
// size (before --downscale); InputError naming the manifest and the field on a mismatch.
void checkManifestAgainstViews(const DatasetManifest& m, const std::vector<std::string>& names,
                               const std::vector<Intrinsics>& full_size);

}  // namespace saresgs
