#include "apps/prefilter_flags.h"

#include <filesystem>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "geometry/error.h"
#include "geometry/io/json_file.h"

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

PrefilterConfig parsePrefilterFlags(const PrefilterFlags& f, PrefilterConfig c, const std::string& prefix,
                                    const std::string& dataset) {
  parseOption(prefix + "scene", [&] {
    if (f.scene.empty()) return;  // the caller's numeric options stand
    if (f.scene != "auto") {
      applySceneType(c, parseSceneType(f.scene));
      return;
    }
    const std::optional<SceneType> t = sceneTypeOfDataset(dataset);
    applySceneType(c, t.value_or(SceneType::kOutdoor));
  });
  parseOption(prefix + "set", [&] { c.set = parseCandidateSet(f.set); });
  parseOption(prefix + "encoding", [&] { parseCoverageEncoding(f.encoding, c.scoring); });
  parseOption(prefix + "score", [&] { c.scoring.criterion = parseCoverageCriterion(f.score); });
  parseOption(prefix + "lifting", [&] { c.lifting = parseLiftingSource(f.lifting); });
  return c;
}

}  // namespace saresgs::apps
