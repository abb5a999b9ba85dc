#include "apps/prefilter_flags.h"

#include <stdexcept>

#include "geometry/error.h"

namespace saresgs::apps {

namespace {

template <class F>
void parseOption(const std::string& option, F&& parse) {
  try {
    parse();
  } catch (const std::invalid_argument& e) {
    throw InputError(option, "value", e.what());
  }
}

}  // namespace

PrefilterConfig parsePrefilterFlags(const PrefilterFlags& f, PrefilterConfig c, const std::string& prefix) {
  parseOption(prefix + "set", [&] { c.set = parseCandidateSet(f.set); });
  parseOption(prefix + "encoding", [&] { parseCoverageEncoding(f.encoding, c.scoring); });
  parseOption(prefix + "score", [&] { c.scoring.criterion = parseCoverageCriterion(f.score); });
  parseOption(prefix + "lifting", [&] { c.lifting = parseLiftingSource(f.lifting); });
  return c;
}

}  // namespace saresgs::apps
