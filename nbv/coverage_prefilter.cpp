// The coverage prefilter joins SA-Point lifting and the occupancy grids (geometry/) to the
// active loop. Until those land, asking for a coverage method is a clear error.
#include <stdexcept>

#include "nbv/active_run.h"

namespace saresgs {

std::unique_ptr<CoveragePrefilter> makeCoveragePrefilter(const Scene&, const PrefilterChoice&, std::uint64_t) {
  throw std::runtime_error("the coverage methods (coverage, sa-hash, sa-resgs) need the SA-Point prefilter, "
                           "which this build does not have yet");
}

}  // namespace saresgs
