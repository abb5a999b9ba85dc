// The one list of methods: every method parses back from its name, names are distinct,
// and what each computes matches the paper's definitions.
#include <gtest/gtest.h>

#include <set>
#include <stdexcept>

#include "nbv/method.h"

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
  EXPECT_FALSE(needsOf(Method::kRandom).fisher || needsOf(Method::kRandom).coverage || needsOf(Method::kRandom).residual);
  EXPECT_FALSE(needsOf(Method::kFvs).fisher || needsOf(Method::kFvs).coverage);
  EXPECT_TRUE(needsOf(Method::kFisher).fisher && !needsOf(Method::kFisher).coverage);
  EXPECT_TRUE(needsOf(Method::kCoverage).coverage && !needsOf(Method::kCoverage).fisher);
  EXPECT_TRUE(needsOf(Method::kSaHash).fisher && needsOf(Method::kSaHash).coverage && !needsOf(Method::kSaHash).residual);
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

}  // namespace
}  // namespace saresgs
