#pragma once
// SA-ResGS's residual supervision subset (paper Sec. 3.3): G_sub = G_rand U G_uncertain,
// with G_rand a random alpha fraction of the Gaussians and G_uncertain the beta fraction
// ranked most uncertain. "Both attributes" is the union of the beta lowest-opacity and
// the beta largest-scale Gaussians; the paper doubles beta for the single-attribute
// variants to compare like with like, which this reading makes exact in count.
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "splat/gaussians.h"

namespace saresgs {

enum class UncertaintyRanking { kBoth, kOpacity, kScale, kRandom };

UncertaintyRanking parseUncertaintyRanking(const std::string& s);  // both|opacity|scale|random
const char* toString(UncertaintyRanking r);

struct ResidualOptions {
  bool enabled = false;
  double alpha = 0.90;  // random fraction
  double beta = 0.10;   // uncertain fraction (per attribute for kBoth)
  double lambda_full = 0.5, lambda_sub = 0.5;
  bool sub_only = false;  // ablation: no full-render loss
  UncertaintyRanking ranking = UncertaintyRanking::kBoth;
};

struct ResidualSubset {
  std::vector<std::uint8_t> mask;  // 1 = in G_sub
  std::vector<int> random;         // G_rand, ascending
  std::vector<int> uncertain;      // G_uncertain, ascending
};

// round(alpha n) Gaussians drawn without replacement, plus the uncertain set. Ties in a
// ranking break by index, so the subset depends only on the model and the generator.
ResidualSubset selectResidualSubset(const Gaussians& g, const ResidualOptions& opt, std::mt19937_64& rng);
// The same into `into`, whose arrays are reused (the ranking's scratch is kept per
// thread): no allocation once the model's size has been seen.
void selectResidualSubset(const Gaussians& g, const ResidualOptions& opt, std::mt19937_64& rng, ResidualSubset& into);

// The top round(fraction n) Gaussians of one ranking: lowest opacity logit, or largest
// maximum log-scale.
std::vector<int> lowestOpacity(const Gaussians& g, double fraction);
std::vector<int> largestScale(const Gaussians& g, double fraction);

}  // namespace saresgs
