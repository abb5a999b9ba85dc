#include "nbv/prefilter_options.h"

#include <algorithm>
#include <optional>
#include <stdexcept>

#include "geometry/error.h"

namespace saresgs {

CandidateSetKind parseCandidateSet(std::string_view text) {
  if (text == "frustum") return CandidateSetKind::kFrustum;
  if (text == "visible") return CandidateSetKind::kVisible;
  throw std::invalid_argument("prefilter set '" + std::string(text) + "': expected frustum or visible");
}
LiftingSource parseLiftingSource(std::string_view text) {
  if (text == "flow") return LiftingSource::kFlow;
  if (text == "depth") return LiftingSource::kDepth;
  if (text == "oracle") return LiftingSource::kOracle;
  throw std::invalid_argument("lifting '" + std::string(text) + "': expected flow, depth or oracle");
}
CoverageCriterion parseCoverageCriterion(std::string_view text) {
  if (text == "xor") return CoverageCriterion::Hamming;
  if (text == "new") return CoverageCriterion::NewCount;
  throw std::invalid_argument("prefilter score '" + std::string(text) + "': expected xor or new");
}
void parseCoverageEncoding(std::string_view text, CoverageScoring& scoring, int min_bits, int max_bits) {
  const std::string t(text);
  if (t == "exact") {
    scoring.encoding = CoverageEncoding::Exact;
    return;
  }
  if (t == "hash:auto") {
    scoring.encoding = CoverageEncoding::Hashed;
    scoring.table_size = 0;
    return;
  }
  if (t.rfind("hash:", 0) != 0)
    throw std::invalid_argument("prefilter encoding '" + t + "': expected hash:auto, hash:K or exact");
  int bits = 0;
  const std::string digits = t.substr(5);
  if (!digits.empty() && digits.size() <= 2 &&
      std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
    bits = std::stoi(digits);
  if (bits < min_bits || bits > max_bits)
    throw std::invalid_argument("prefilter encoding '" + t + "': expected hash:auto, hash:" + std::to_string(min_bits) +
                                " .. hash:" + std::to_string(max_bits) + " or exact");
  scoring.encoding = CoverageEncoding::Hashed;
  scoring.table_size = std::size_t{1} << bits;
}

SceneType parseSceneType(std::string_view text) {
  if (text == "indoor") return SceneType::kIndoor;
  if (text == "outdoor") return SceneType::kOutdoor;
  throw std::invalid_argument("scene type '" + std::string(text) + "': expected indoor or outdoor");
}

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

}  // namespace saresgs
