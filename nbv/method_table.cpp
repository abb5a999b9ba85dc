// The method registry's table and what method.h answers from it (a file of its own: the
// table names each method's selector, nbv/selection_step.h, whose context needs method.h).
#include "nbv/method.h"

#include <stdexcept>

#include "nbv/selection_step.h"

namespace saresgs {

namespace {

struct MethodRow {
  Method method;
  const char* name;
  MethodNeeds needs;  // fisher, coverage, residual, surface
  SelectFn select;
};

// The list of methods (see method.h).
constexpr MethodRow kMethodTable[] = {
    {Method::kRandom, "random", {false, false, false}, selectRandomView},
    {Method::kFvs, "fvs", {false, false, false}, selectFarthestView},
    {Method::kFisher, "fisher", {true, false, false}, selectFisherView},
    {Method::kCoverage, "coverage", {false, true, false}, selectCoverageView},
    {Method::kSaHash, "sa-hash", {true, true, false}, selectFisherView},
    {Method::kSaResgs, "sa-resgs", {true, true, true}, selectFisherView},
    {Method::kResgs, "resgs", {true, false, true}, selectFisherView},
    // D-optimal Fisher: the log-det gain instead of the trace (selectors.h).
    {Method::kFisherLogDet, "fisher-logdet", {true, false, false}, selectFisherView},
    // Fisher information and occlusion-aware coverage of unobserved surface (selectors.h).
    {Method::kHybrid, "hybrid", {true, false, false, true}, selectFisherView},
    // Greedy k-median on pose distances over the train views (kmedianGains): no model.
    {Method::kKmedian, "kmedian", {false, false, false}, selectKmedianView},
    // FisherRF's trace on the k-median's top fraction (ActiveOptions::gate_keep): the
    // paper's shape (a prefilter, then Fisher) with a representativeness prefilter.
    {Method::kKmedianFisher, "kmedian-fisher", {true, false, false}, selectGatedFisherView},
    // FisherRF's trace on farthest view sampling's top fraction (the largest gaps).
    {Method::kFvsFisher, "fvs-fisher", {true, false, false}, selectGatedFisherView},
    // kmedian-fisher on a clustered capture, fvs-fisher on any other (captureClustering
    // against ActiveOptions::adaptive_clustering).
    {Method::kAdaptive, "adaptive", {true, false, false}, selectGatedFisherView},
    // Greedy k-median over the train views, each weighted by FisherRF's score of it: the
    // view that brings a held view nearest to the views the model is least sure of
    // (kmedianGains with weights). No setting.
    {Method::kFisherKmedian, "fisher-kmedian", {true, false, false}, selectFisherView},
    // Not a method for real captures: greedy k-median on pose distances over the dataset's
    // test views, which it is told. What a selector aimed at the views people will look at
    // could reach with the same budget; the verdict's tables measure the others against it.
    {Method::kOracle, "oracle", {false, false, false}, selectOracleView},
    // The view that most reduces the predicted variance summed over the pool of path views
    // (nbv/path_variance.h), each parameter group damped relative to its held information.
    {Method::kPathVariance, "path-variance", {true, false, false}, selectPathVarianceView},
    // A selector function given by the caller (ActiveOptions::custom_selector: the Python
    // module's selectors); plain training, nothing precomputed.
    {Method::kCustom, "custom", {false, false, false}, selectCustomView},
};

const MethodRow& rowOf(Method m) {
  for (const MethodRow& r : kMethodTable)
    if (r.method == m) return r;
  throw std::logic_error("method missing from kMethodTable");
}

}  // namespace

const std::vector<Method>& allMethods() {
  static const std::vector<Method> all = [] {
    std::vector<Method> v;
    for (const MethodRow& r : kMethodTable) v.push_back(r.method);
    return v;
  }();
  return all;
}

const char* toString(Method m) { return rowOf(m).name; }
MethodNeeds needsOf(Method m) { return rowOf(m).needs; }
SelectFn selectorOf(Method m) { return rowOf(m).select; }

Method parseMethod(const std::string& s) {
  for (const MethodRow& r : kMethodTable)
    if (s == r.name) return r.method;
  throw std::invalid_argument("method '" + s + "': expected one of " + methodChoices(", "));
}

std::vector<std::string> methodNames() {
  std::vector<std::string> v;
  for (const MethodRow& r : kMethodTable) v.push_back(r.name);
  return v;
}

std::string methodChoices(const char* separator) {
  std::string s;
  for (const MethodRow& r : kMethodTable) s += (s.empty() ? "" : separator) + std::string(r.name);
  return s;
}

}  // namespace saresgs
