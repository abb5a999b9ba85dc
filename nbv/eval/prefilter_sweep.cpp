#include "nbv/eval/prefilter_sweep.h"

#include <algorithm>
#include <chrono>
#include <numeric>
#include <random>
#include <stdexcept>

#include "geometry/occupancy/candidate_sets.h"
#include "geometry/occupancy/coverage_score.h"
#include "geometry/occupancy/occupancy_grid.h"
#include "geometry/error.h"
#include "geometry/io/json_file.h"
#include "nbv/initial_views.h"
#include "nbv/selection_seconds.h"

namespace saresgs {

namespace {

using Clock = std::chrono::steady_clock;

// The protocol's initial views, then random train views (seeded), `count` in all.
std::vector<int> observedOrder(const Scene& scene, int count, std::uint64_t seed) {
  std::vector<Eigen::Vector3d> centers;
  for (int v : scene.train) centers.push_back(scene.views[static_cast<std::size_t>(v)].camera.center());
  std::vector<int> order;
  for (int i : farthestPointSampling(centers, std::min(4, count), 0))
    order.push_back(scene.train[static_cast<std::size_t>(i)]);
  std::vector<int> rest;
  for (int v : scene.train)
    if (std::find(order.begin(), order.end(), v) == order.end()) rest.push_back(v);
  std::mt19937_64 rng(seed);
  std::shuffle(rest.begin(), rest.end(), rng);
  for (int v : rest) {
    if (static_cast<int>(order.size()) >= count) break;
    order.push_back(v);
  }
  return order;
}

}  // namespace

std::vector<CoverageScoring> SweepSpec::defaultEncodings() {
  std::vector<CoverageScoring> e;
  for (int bits = 11; bits <= 19; ++bits)
    e.push_back({CoverageEncoding::Hashed, CoverageCriterion::Hamming, std::size_t{1} << bits});
  e.push_back({CoverageEncoding::Exact, CoverageCriterion::Hamming, 0});
  return e;
}

nlohmann::json toJson(const SweepReport& r) {
  nlohmann::json res = {{"scene", r.scene}, {"dataset", r.dataset}, {"lifting", r.lifting}, {"reference", r.reference}};
  if (r.resolution > 0)
    res["grid"] = {{"scene_type", r.scene_type},
                   {"resolution", r.resolution},
                   {"min_points", r.min_points},
                   {"scene_voxels", r.scene_voxels}};
  for (const SweepRow& w : r.rows)
    res["rows"].push_back({{"set", w.set},
                           {"encoding", w.encoding},
                           {"score", w.score},
                           {"views", w.views},
                           {"candidates", w.candidates},
                           {"overlap", w.overlap},
                           {"kendall_tau", w.kendall_tau},
                           {"seconds_scoring", w.seconds_scoring},
                           {"seconds_sets", w.seconds_sets},
                           {"load", w.load}});
  return res;
}

namespace {
constexpr long long kMaxSweepCount = 2'000'000'000;
}  // namespace

SweepReport sweepReportFromJson(const nlohmann::json& j, const std::string& source) {
  SweepReport r;
  auto text = [&](const nlohmann::json& o, const char* key, const std::string& path) {
    return jsonString(jsonMember(o, key, source, path), source, jsonPath(path, key));
  };
  auto number = [&](const nlohmann::json& o, const char* key, const std::string& path) {
    return jsonNumber(jsonMember(o, key, source, path), source, jsonPath(path, key));
  };
  auto count = [&](const nlohmann::json& o, const char* key, const std::string& path) {
    return static_cast<int>(
        jsonInteger(jsonMember(o, key, source, path), source, jsonPath(path, key), 0, kMaxSweepCount));
  };
  r.scene = text(j, "scene", "");
  r.dataset = text(j, "dataset", "");
  r.lifting = text(j, "lifting", "");
  r.reference = text(j, "reference", "");
  if (const nlohmann::json* g = jsonFind(j, "grid", source, "")) {
    jsonObject(*g, source, "grid");
    r.scene_type = text(*g, "scene_type", "grid");
    r.resolution = count(*g, "resolution", "grid");
    r.min_points = count(*g, "min_points", "grid");
    r.scene_voxels = static_cast<std::size_t>(count(*g, "scene_voxels", "grid"));
  }
  const auto& rows = jsonArray(jsonMember(j, "rows", source, ""), source, "rows");
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const std::string at = jsonPath("rows", i);
    const auto& w = rows[i];
    r.rows.push_back({text(w, "set", at), text(w, "encoding", at), text(w, "score", at), count(w, "views", at),
                      count(w, "candidates", at), number(w, "overlap", at), number(w, "kendall_tau", at),
                      number(w, "seconds_scoring", at), number(w, "seconds_sets", at),
                      jsonFind(w, "load", source, at) ? number(w, "load", at) : 0.0});
  }
  return r;
}

double kendallTauB(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) throw std::invalid_argument("kendallTauB: sizes differ");
  long long concordant = 0, discordant = 0, ties_a = 0, ties_b = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = i + 1; j < a.size(); ++j) {
      const double da = a[i] - a[j], db = b[i] - b[j];
      if (da == 0 && db == 0) continue;  // tied in both: counted in neither denominator term
      if (da == 0)
        ++ties_a;
      else if (db == 0)
        ++ties_b;
      else if ((da > 0) == (db > 0))
        ++concordant;
      else
        ++discordant;
    }
  const double n1 = static_cast<double>(concordant + discordant + ties_a);
  const double n2 = static_cast<double>(concordant + discordant + ties_b);
  if (n1 == 0 || n2 == 0) return n1 == n2 ? 1.0 : 0.0;
  return static_cast<double>(concordant - discordant) / std::sqrt(n1 * n2);
}

double topOverlap(const std::vector<double>& a, const std::vector<double>& b, double fraction) {
  std::vector<int> idx(a.size());
  std::iota(idx.begin(), idx.end(), 0);
  const std::vector<int> ta = topFraction(a, idx, fraction), tb = topFraction(b, idx, fraction);
  std::vector<int> both;
  std::set_intersection(ta.begin(), ta.end(), tb.begin(), tb.end(), std::back_inserter(both));
  return tb.empty() ? 1.0 : static_cast<double>(both.size()) / static_cast<double>(tb.size());
}

std::vector<SweepRow> prefilterSweep(const Scene& scene, const SweepSpec& spec, const ViewRenderer& render,
                                     const DepthRenderer& depth, std::uint64_t seed, const PrefilterConfig& grid,
                                     PrefilterRegime* regime) {
  if (spec.view_counts.empty()) throw std::invalid_argument("prefilter sweep: no view counts");
  std::vector<int> counts = spec.view_counts;
  std::sort(counts.begin(), counts.end());
  const std::vector<int> order = observedOrder(scene, counts.back(), seed);

  PrefilterConfig config = grid;
  config.lifting = spec.lifting;
  config.scoring = {CoverageEncoding::Exact, CoverageCriterion::Hamming, 0};
  std::unique_ptr<CoveragePrefilter> pf = makeCoveragePrefilter(scene, config);
  const OccupancyGrids& grids = pf->grids();
  if (regime) *regime = pf->regime();

  // Every train view's candidate sets, once per kind, timed per view; the reference
  // always needs the visible sets, whether or not they are swept.
  std::vector<CandidateSetKind> kinds = spec.sets;
  if (std::find(kinds.begin(), kinds.end(), CandidateSetKind::kVisible) == kinds.end())
    kinds.push_back(CandidateSetKind::kVisible);
  std::map<CandidateSetKind, std::vector<VoxelSet>> sets;
  std::map<CandidateSetKind, std::vector<double>> set_seconds;
  const CandidateSetBuilder builder(grids);
  for (CandidateSetKind kind : kinds) {
    builder.prepare(kind);  // the tracer's construction is not part of the per-view time
    for (int v : scene.train) {
      const Camera& cam = scene.views[static_cast<std::size_t>(v)].camera;
      const auto t0 = Clock::now();
      sets[kind].push_back(builder.build(cam, kind, config.visible_stride));
      set_seconds[kind].push_back(secondsSince(t0));
    }
  }

  std::vector<SweepRow> rows;
  int observed = 0;
  SelectionSeconds ignored;
  for (int count : counts) {
    pf->observe(std::vector<int>(order.begin() + observed, order.begin() + count), render, depth, ignored);
    observed = count;
    const VoxelSet obs = grids.observedSceneVoxels();
    std::vector<std::size_t> cand;  // positions in scene.train
    for (std::size_t i = 0; i < scene.train.size(); ++i)
      if (std::find(order.begin(), order.begin() + count, scene.train[i]) == order.begin() + count) cand.push_back(i);
    auto pick = [&](CandidateSetKind kind) {
      std::vector<VoxelSet> s;
      for (std::size_t i : cand) s.push_back(sets.at(kind)[i]);
      return s;
    };
    auto values = [&](const std::vector<VoxelSet>& s, const CoverageScoring& o) {
      std::vector<double> out;
      for (const auto& c : scoreCandidates(obs, s, grids.sceneCount(), o))
        out.push_back(criterionValue(c, o.criterion));
      return out;
    };
    for (CoverageCriterion score : spec.scores) {
      const std::vector<double> ref = values(pick(CandidateSetKind::kVisible), {CoverageEncoding::Exact, score, 0});
      for (CandidateSetKind kind : spec.sets) {
        const std::vector<VoxelSet> s = pick(kind);
        double set_s = 0;
        for (std::size_t i : cand) set_s += set_seconds.at(kind)[i];
        for (CoverageScoring o : spec.encodings) {
          o.criterion = score;
          // hash:auto resolves here as in the active loop (load <= 0.5 on this grid).
          if (o.encoding == CoverageEncoding::Hashed && o.table_size == 0)
            o.table_size = hashTableSizeFor(grids.sceneCount());
          std::vector<double> times, v;
          for (int r = 0; r < std::max(1, spec.timing_repeats); ++r) {
            const auto t0 = Clock::now();
            v = values(s, o);
            times.push_back(secondsSince(t0));
          }
          std::nth_element(times.begin(), times.begin() + static_cast<long>(times.size() / 2), times.end());
          SweepRow row;
          row.set = toString(kind);
          row.encoding = encodingName(o);
          row.score = toString(score);
          row.views = count;
          row.candidates = static_cast<int>(cand.size());
          row.overlap = topOverlap(v, ref, spec.keep_fraction);
          row.kendall_tau = kendallTauB(v, ref);
          row.seconds_scoring = times[times.size() / 2];
          row.seconds_sets = set_s;
          if (o.encoding == CoverageEncoding::Hashed)
            row.load = static_cast<double>(grids.sceneCount()) / static_cast<double>(o.table_size);
          rows.push_back(row);
        }
      }
    }
  }
  return rows;
}

}  // namespace saresgs
