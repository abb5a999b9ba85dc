#pragma once
// The options of a synthetic scene in one call, for the tests and fuzz targets that make
// small scenes. Kept free of GoogleTest (as ring_scene.h) so that the fuzz targets can use it.
#include <cstdint>
#include <string>

#include "geometry/synth/synthetic_scene.h"

namespace saresgs::test {

// `layout` rendered at w x h with `seed`, `num_views` views (0: the layout's default
// count); everything else as SyntheticOptions has it (procedural meshes and textures).
inline SyntheticOptions syntheticOptions(const std::string& layout, int w, int h, std::uint64_t seed = 0,
                                         int num_views = 0) {
  SyntheticOptions o;
  o.layout = layout;
  o.width = w;
  o.height = h;
  o.seed = seed;
  o.num_views = num_views;
  return o;
}

}  // namespace saresgs::test
