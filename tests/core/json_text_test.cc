// Tests of core/json_text.h: repeated keys are errors naming their path; syntax errors name the
// line and column; both through Config too.
#include "core/json_text.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/config.h"
#include "tests/test_util.h"

namespace mmh {
namespace {

using test_util::ErrorOf;
using ::testing::HasSubstr;

TEST(ParseJsonText, ParsesValidJson) {
  const nlohmann::json j = ParseJsonText(R"({"a": {"b": [1, {"c": 2}, {"c": 3}]}, "d": "x"})", "s");
  EXPECT_EQ(j["a"]["b"][2]["c"], 3);
  EXPECT_EQ(j["d"], "x");
}

TEST(ParseJsonText, RepeatedKeysAreErrorsNamingTheirPath) {
  EXPECT_THAT(ErrorOf([] { ParseJsonText(R"({"montage": {}, "montage": {}})", "c.json"); }),
              HasSubstr("c.json: key 'montage': got a key that appears twice in one object"));
  EXPECT_THAT(ErrorOf([] {
                ParseJsonText(R"({"montage": {"dtw": {"lambda": 1, "lambda": 2}}})", "c.json");
              }),
              HasSubstr("key 'montage.dtw.lambda'"));
  EXPECT_THAT(ErrorOf([] { ParseJsonText(R"({"a": [{"x": 1}, 5, {"y": 1, "y": 2}]})", "c.json"); }),
              HasSubstr("key 'a[2].y'"));
  // The same key in two objects is fine.
  ParseJsonText(R"({"a": {"x": 1}, "b": {"x": 1}, "c": [{"x": 1}, {"x": 2}]})", "c.json");
}

TEST(ParseJsonText, SyntaxErrorsNameLineAndColumn) {
  const std::string message = ErrorOf([] { ParseJsonText("{\n  \"a\": 1,\n  oops\n}", "c.json"); });
  EXPECT_THAT(message, HasSubstr("c.json:3:3: invalid JSON"));
  EXPECT_THAT(ErrorOf([] { ParseJsonText(R"({"a": 1e999})", "c.json"); }),
              HasSubstr("expected a number a double can hold"));
}

TEST(ParseJsonText, ConfigRefusesRepeatedSectionsAndKeys) {
  test_util::TempDir dir;
  test_util::WriteText(dir / "c.json", R"({"montage": {"dtw": {}}, "montage": {}})");
  EXPECT_THAT(ErrorOf([&] { Config::Load(dir / "c.json"); }),
              HasSubstr((dir / "c.json").string() + ": key 'montage': got a key that appears"));
  Config config;
  EXPECT_THAT(ErrorOf([&] { config.Set(R"(montage={"a": 1, "a": 2})"); }),
              HasSubstr("key 'a': got a key that appears twice"));
  // /dev/zero is refused at once, naming it.
  EXPECT_THAT(ErrorOf([] { Config::Load("/dev/zero"); }), HasSubstr("/dev/zero: got binary data"));
}

}  // namespace
}  // namespace mmh
