#pragma once
// The coverage prefilter's textual options, as `saresgs active` and `saresgs coverage`
// take them, parsed once into the typed PrefilterConfig (nbv/coverage_prefilter.h).
#include <string>

#include "nbv/coverage_prefilter.h"

namespace saresgs::apps {

struct PrefilterFlags {
  std::string set = "frustum", encoding = "hash:auto", score = "xor", lifting = "flow";
  // indoor | outdoor | auto (the dataset's built-in layout says; outdoor otherwise); empty:
  // leave the base's resolution and points per voxel
  std::string scene = "auto";
};

// `base` with the flags parsed in; a bad value throws InputError naming the option
// (`option_prefix` + "set", ...) and what was expected.
// `dataset` is read only for `scene` auto (its manifest.json's layout; a dataset that is
// missing or has none counts as outdoor).
PrefilterConfig parsePrefilterFlags(const PrefilterFlags& f, PrefilterConfig base, const std::string& option_prefix,
                                    const std::string& dataset = {});

}  // namespace saresgs::apps
