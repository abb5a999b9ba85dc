// The one list of methods: every method parses back from its name, names are distinct,
// and what each computes matches the paper's definitions.
#include <gtest/gtest.h>

#include <set>
#include <stdexcept>

#include "nbv/method.h"
#include "nbv/active_settings.h"
#include "nbv/preset.h"

namespace saresgs {
namespace {

TEST(Method, EveryMethodParsesFromItsNameAndNamesAreDistinct) {
  std::set<std::string> names;
  for (Method m : allMethods()) {
    EXPECT_EQ(parseMethod(toString(m)), m);
    EXPECT_TRUE(names.insert(toString(m)).second) << toString(m);
    EXPECT_NE(methodChoices().find(toString(m)), std::string::npos);
  }
  EXPECT_EQ(methodNames().size(), allMethods().size());
  for (std::size_t i = 0; i < allMethods().size(); ++i) EXPECT_EQ(methodNames()[i], toString(allMethods()[i]));
}

TEST(Method, WhatEachMethodComputes) {
  EXPECT_FALSE(needsOf(Method::kRandom).fisher || needsOf(Method::kRandom).coverage ||
               needsOf(Method::kRandom).residual);
  EXPECT_FALSE(needsOf(Method::kFvs).fisher || needsOf(Method::kFvs).coverage);
  EXPECT_TRUE(needsOf(Method::kFisher).fisher && !needsOf(Method::kFisher).coverage);
  EXPECT_TRUE(needsOf(Method::kCoverage).coverage && !needsOf(Method::kCoverage).fisher);
  EXPECT_TRUE(needsOf(Method::kSaHash).fisher && needsOf(Method::kSaHash).coverage &&
              !needsOf(Method::kSaHash).residual);
  const MethodNeeds sa = needsOf(Method::kSaResgs);
  EXPECT_TRUE(sa.fisher && sa.coverage && sa.residual);
  EXPECT_TRUE(needsOf(Method::kResgs).residual && !needsOf(Method::kResgs).coverage);
}

TEST(Method, UnknownNameListsTheChoices) {
  try {
    parseMethod("clairvoyant");
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("'clairvoyant'"), std::string::npos) << msg;
    for (Method m : allMethods()) EXPECT_NE(msg.find(toString(m)), std::string::npos) << msg;
  }
}

// The one function both front ends (saresgs active, Python's ActiveRun) turn settings into
// options with: an empty setting keeps the preset's value, a given one replaces it.
TEST(ActiveSettings, KeepThePresetWhereNothingIsGivenAndApplyWhatIs) {
  const ActiveOptions quick = presetOptions(Preset::kQuick);
  ActiveSettings s;
  s.method = "fisher";
  s.seed = 7;
  const ActiveOptions a = activeOptionsFrom(s);
  EXPECT_EQ(a.method, Method::kFisher);
  EXPECT_EQ(a.seed, 7u);
  EXPECT_EQ(a.interval, quick.interval);
  EXPECT_EQ(a.total_iterations, quick.total_iterations);
  EXPECT_EQ(a.final_iterations, quick.final_iterations);
  EXPECT_EQ(a.max_views, quick.max_views);
  EXPECT_EQ(a.trainer.densify.max_gaussians, quick.trainer.densify.max_gaussians);
  EXPECT_EQ(a.gate_keep, quick.gate_keep);
  EXPECT_EQ(a.path_variance_kappa, quick.path_variance_kappa);
  EXPECT_TRUE(a.plain_refit);

  s.preset = "paper";
  s.threads = 1;
  s.max_views = 12;
  s.interval = 40;
  s.min_iterations = 900;
  s.final_iterations = 0;
  s.max_gaussians = 5000;
  s.plain_refit = false;
  s.final_residual = true;
  s.gate_keep = 0.3;
  s.path_variance_kappa = 0.1;
  s.adaptive_clustering = 0.5;
  s.hybrid_weight = 0.25;
  s.fisher_lambda = 1e-3;
  const ActiveOptions b = activeOptionsFrom(s);
  EXPECT_EQ(b.trainer.raster.execution.threads, 1);
  EXPECT_EQ(b.final_trainer.raster.execution.threads, 1);
  EXPECT_EQ(b.max_views, 12);
  EXPECT_EQ(b.interval, 40);
  EXPECT_EQ(b.total_iterations, 900);
  EXPECT_EQ(b.final_iterations, 0);
  EXPECT_EQ(b.trainer.densify.max_gaussians, 5000u);
  EXPECT_EQ(b.final_trainer.densify.max_gaussians, 5000u);
  EXPECT_FALSE(b.plain_refit);
  EXPECT_TRUE(b.final_residual);
  EXPECT_EQ(b.gate_keep, 0.3);
  EXPECT_EQ(b.path_variance_kappa, 0.1);
  EXPECT_EQ(b.adaptive_clustering, 0.5);
  EXPECT_EQ(b.hybrid_weight, 0.25);
  EXPECT_EQ(b.fisher_lambda, 1e-3);
  // The paper preset's schedule underneath (not the quick one's quarter).
  EXPECT_EQ(b.trainer.densify.until_iter, presetOptions(Preset::kPaper).trainer.densify.until_iter);

  s.preset = "fast";
  EXPECT_THROW((void)activeOptionsFrom(s), std::invalid_argument);
}

}  // namespace
}  // namespace saresgs
