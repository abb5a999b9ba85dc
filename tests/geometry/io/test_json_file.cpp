// Typed JSON fields: wrong types, ranges and missing members name the file and the field.
#include <gtest/gtest.h>

#include "common/test_support.h"
#include "geometry/io/json_file.h"

using namespace saresgs;
using nlohmann::json;

namespace {

// The message of the InputError that f throws ("" when none).
template <class F>
std::string messageOf(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(JsonFields, ReturnsValuesOfTheRightType) {
  const json j =
      json::parse(R"({"n": 2.5, "i": 7, "big": 2e9, "s": "x", "b": true, "a": [1, 2], "names": ["p", "q"]})");
  EXPECT_EQ(jsonNumber(jsonMember(j, "n", "f.json", ""), "f.json", "n"), 2.5);
  EXPECT_EQ(jsonInteger(j["i"], "f.json", "i", 0, 10), 7);
  EXPECT_EQ(jsonInteger(j["big"], "f.json", "big", 0, 3'000'000'000LL), 2'000'000'000LL);
  EXPECT_EQ(jsonString(j["s"], "f.json", "s"), "x");
  EXPECT_TRUE(jsonBool(j["b"], "f.json", "b"));
  EXPECT_EQ(jsonIntegers(j["a"], "f.json", "a", 0, 5), (std::vector<long long>{1, 2}));
  EXPECT_EQ(jsonStrings(j["names"], "f.json", "names"), (std::vector<std::string>{"p", "q"}));
  EXPECT_EQ(jsonFind(j, "none", "f.json", ""), nullptr);
  EXPECT_EQ(jsonPath("", "a"), "a");
  EXPECT_EQ(jsonPath("a", "b"), "a.b");
  EXPECT_EQ(jsonPath("a", 3), "a[3]");
}

TEST(JsonFields, WrongTypesAndRangesNameFileAndField) {
  const json j = json::parse(R"({"n": "abc", "i": 1.5, "neg": -1, "huge": 1e30, "arr": [1, "two"], "obj": [1]})");
  const std::string f = "dir/manifest.json";
  std::string m = messageOf([&] { jsonNumber(j["n"], f, "width"); });
  EXPECT_NE(m.find("dir/manifest.json: width: expected a number, got \"abc\""), std::string::npos) << m;
  m = messageOf([&] { jsonInteger(j["i"], f, "num_views", 0, 100); });
  EXPECT_NE(m.find("num_views: expected a whole number in 0..100, got 1.5"), std::string::npos) << m;
  EXPECT_TRUE(test::throwsInputError([&] { jsonInteger(j["neg"], f, "seed", 0, 10); }, f, "seed"));
  EXPECT_TRUE(test::throwsInputError(
      [&] { jsonInteger(j["huge"], f, "seed", 0, std::numeric_limits<long long>::max()); }, f, "seed"));
  EXPECT_TRUE(test::throwsInputError([&] { jsonNumberIn(j["huge"], f, "keep", 0, 1); }, f, "keep"));
  m = messageOf([&] { jsonIntegers(j["arr"], f, "seeds", 0, 10); });
  EXPECT_NE(m.find("seeds[1]: expected a whole number"), std::string::npos) << m;
  EXPECT_TRUE(test::throwsInputError([&] { jsonMember(j["obj"], "split", f, "objects[0]"); }, f, "objects[0]"));
  m = messageOf([&] { jsonMember(j, "width", f, "camera"); });
  EXPECT_NE(m.find("camera.width: missing"), std::string::npos) << m;
  EXPECT_TRUE(test::throwsInputError([&] { jsonArray(j["arr"], f, "frames", 1); }, f, "at most 1"));
  EXPECT_TRUE(test::throwsInputError([&] { jsonString(j["i"], f, "layout"); }, f, "layout"));
  EXPECT_TRUE(test::throwsInputError([&] { jsonBool(j["i"], f, "specular"); }, f, "specular"));
  // A long value is cut short in the message.
  const json longer = std::string(200, 'x');
  m = messageOf([&] { jsonNumber(longer, f, "w"); });
  EXPECT_LT(m.size(), 120u) << m;
}
