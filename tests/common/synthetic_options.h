#pragma once
// The options of a synthetic scene in one call, for the tests and fuzz targets that make
// small scenes. Kept free of GoogleTest (as ring_scene.h) so that the fuzz targets can use it.
#include <cstdint>
#include <string>

#include "geometry/synth/synthetic_scene.h"

namespace saresgs::test {

// The library's own (geometry/synth/synthetic_scene.h), under the name the tests use.
using saresgs::syntheticOptions;

}  // namespace saresgs::test
