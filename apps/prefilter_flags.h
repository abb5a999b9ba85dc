#pragma once
// The coverage prefilter's textual options, as `saresgs active` and `saresgs coverage`
// take them, parsed once into the typed PrefilterConfig (nbv/coverage_prefilter.h).
#include <string>

#include "nbv/coverage_prefilter.h"

namespace saresgs::apps {

struct PrefilterFlags {
  std::string set = "frustum", encoding = "hash:13", score = "xor", lifting = "flow";
};

// `base` with the flags parsed in; a bad value throws InputError naming the option
// (`option_prefix` + "set", ...) and what was expected.
PrefilterConfig parsePrefilterFlags(const PrefilterFlags& f, PrefilterConfig base, const std::string& option_prefix);

}  // namespace saresgs::apps
