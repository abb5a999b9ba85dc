#pragma once
// The coverage prefilter's options as text, where every front end takes them: `saresgs
// active --prefilter-*`, `saresgs coverage --*`, the Python module's keyword arguments and
// an ablation grid's sweep. Parsed once into the typed PrefilterConfig
// (nbv/coverage_prefilter.h); nothing further in is a string.
#include <string>
#include <string_view>

#include "nbv/coverage_prefilter.h"

namespace saresgs {

// Parsers of one option each; each throws std::invalid_argument naming the value and
// what was expected. An encoding is "exact" or "hash:K" with K in [min_bits, max_bits]
// (the active loop takes the paper's 2^11..2^19; the sweep goes beyond); it sets the
// encoding and table size of `scoring` and leaves its criterion alone.
CandidateSetKind parseCandidateSet(std::string_view text);        // frustum | visible
LiftingSource parseLiftingSource(std::string_view text);          // flow | depth | oracle
CoverageCriterion parseCoverageCriterion(std::string_view text);  // xor | new
void parseCoverageEncoding(std::string_view text, CoverageScoring& scoring, int min_bits = 11, int max_bits = 19);
SceneType parseSceneType(std::string_view text);  // indoor | outdoor

// All of them together, as the front ends hold them.
struct PrefilterFlags {
  std::string set = "frustum", encoding = "hash:auto", score = "xor", lifting = "flow";
  // indoor | outdoor | auto (the dataset's built-in layout says; outdoor otherwise); empty:
  // leave the base's resolution and points per voxel
  std::string scene = "auto";
};

// `base` with the flags parsed in; a bad value throws InputError naming the option
// (`option_prefix` + "set", ...) and what was expected. `dataset` is read only for `scene`
// auto (its manifest.json's layout; a dataset that is missing or has none counts as
// outdoor).
PrefilterConfig parsePrefilterFlags(const PrefilterFlags& f, PrefilterConfig base, const std::string& option_prefix,
                                    const std::string& dataset = {});

}  // namespace saresgs
