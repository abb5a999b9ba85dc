#pragma once
// The view-selection methods of an active run. kMethodTable in method_table.cpp is the one
// list: names, parsing, the CLI's choices, the ablation's checks, what each method
// computes and the function that chooses its views all come from it, so adding a method
// means adding its row (and its enum value) there, and its function
// (nbv/selection_step.h).
#include <string>
#include <vector>

namespace saresgs {

struct SelectionStep;
struct SelectionLog;

enum class Method {
  kRandom,
  kFvs,
  kFisher,
  kCoverage,
  kSaHash,
  kSaResgs,
  kResgs,
  kFisherLogDet,
  kHybrid,
  kKmedian,
  kKmedianFisher,
  kFvsFisher,
  kAdaptive,
  kFisherKmedian,
  kOracle,
  kPathVariance,
  kCustom
};

// What a method computes; everything else is left out of its run.
struct MethodNeeds {
  bool fisher = false;    // renders and squared gradients of candidates
  bool coverage = false;  // SA-Points, occupancy grids, prefilter
  bool residual = false;  // residual supervision in training
  bool surface = false;   // Embree-visible coverage of SfM surface (nbv/surface_coverage.h)
};

// Every method, in the table's order.
const std::vector<Method>& allMethods();
const char* toString(Method m);
// Throws std::invalid_argument naming the value and the accepted names.
Method parseMethod(const std::string& s);
MethodNeeds needsOf(Method m);
// How the method chooses the next view (nbv/selection_step.h).
using SelectFn = int (*)(SelectionStep& step, SelectionLog& log);
SelectFn selectorOf(Method m);
// The names in table order ("random", "fvs", ...), and joined for help texts
// ("random | fvs | ...").
std::vector<std::string> methodNames();
std::string methodChoices(const char* separator = " | ");

}  // namespace saresgs
