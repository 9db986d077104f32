#include "pipeline/regress.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "tests/test_util.h"

namespace mmh::pipeline {
namespace {

using test_util::ErrorOf;
using test_util::TempDir;
using test_util::WriteText;

TEST(RegressTest, ReadsABaselineAndResolvesPathsAgainstItsRoot) {
  TempDir dir;
  WriteText(dir / "baseline.json", R"({"root": "../x", "scenarios": [
    {"name": "a", "config": "configs/a.json", "set": ["run.takes=2"],
     "metrics": {"m.n": {"value": 1.5, "tolerance": 0.1, "better": "lower"},
                 "k": {"value": 2, "tolerance": 0.01, "relative": true}}}]})");
  const Baseline b = ReadBaseline(dir.path());
  ASSERT_EQ(b.scenarios.size(), 1u);
  const Scenario& s = b.scenarios[0];
  EXPECT_EQ(s.config, (dir.path() / "../x").lexically_normal() / "configs/a.json");
  EXPECT_EQ(s.sets, std::vector<std::string>{"run.takes=2"});
  ASSERT_EQ(s.metrics.size(), 2u);
  EXPECT_EQ(s.metrics[0].first, "k");  // JSON objects read in key order
  EXPECT_TRUE(s.metrics[0].second.relative);
  EXPECT_EQ(s.metrics[1].second.better, Better::kLower);
}

TEST(RegressTest, MalformedBaselinesAreNamed) {
  TempDir dir;
  EXPECT_NE(ErrorOf([&] { ReadBaseline(dir.path()); }).find("baseline.json"), std::string::npos);
  const std::pair<const char*, const char*> cases[] = {
      {"{", "invalid JSON"},
      {R"({"scenarios": []})", "root"},
      {R"({"root": ".", "scenarios": []})", "non-empty array"},
      {R"({"root": ".", "scenario": []})", "scenario"},
      {R"({"root": ".", "scenarios": [{"name": "a", "config": "c", "metrics": {"x": {"value": 1, "tolerance": -1}}}]})",
       "scenarios[0].metrics.x.tolerance"},
      {R"({"root": ".", "scenarios": [{"name": "a", "config": "c", "metrics": {"x": {"value": 1, "tolerance": 1, "better": "up"}}}]})",
       "one of higher, lower"},
      {R"({"root": ".", "scenarios": [{"name": "a", "config": "c", "metrics": {"x": {"value": 1, "tolerence": 1}}}]})",
       "tolerence"},
      {R"({"root": ".", "scenarios": [{"name": "a", "config": "c", "metrics": {}}, {"name": "a", "config": "c", "metrics": {}}]})",
       "a name not used before"},
  };
  for (const auto& [text, expected] : cases) {
    WriteText(dir / "baseline.json", text);
    const std::string error = ErrorOf([&] { ReadBaseline(dir.path()); });
    EXPECT_NE(error.find(expected), std::string::npos) << text << "\n" << error;
    EXPECT_NE(error.find("baseline.json"), std::string::npos) << error;
  }
}

TEST(RegressTest, VerdictsFollowTheToleranceAndTheBetterDirection) {
  Scenario s;
  s.name = "s";
  s.metrics = {{"a", {1.0, 0.1, false, Better::kHigher}},    // 1.05: pass
               {"b", {1.0, 0.1, false, Better::kHigher}},    // 1.2: improved
               {"c", {1.0, 0.1, false, Better::kHigher}},    // 0.8: regressed
               {"d", {1.0, 0.1, false, Better::kLower}},     // 1.2: regressed
               {"e", {100.0, 0.01, true, Better::kEither}},  // 100.5: pass (1 allowed)
               {"f", {100.0, 0.01, true, Better::kEither}},  // 98: regressed
               {"g", {1.0, 0.1, false, Better::kEither}}};   // missing
  const nlohmann::json metrics = {{"a", 1.05}, {"b", 1.2},   {"c", 0.8},
                                  {"d", 1.2},  {"e", 100.5}, {"f", 98.0}};
  const auto c = CompareWithBaseline(s, metrics);
  ASSERT_EQ(c.size(), 7u);
  const Verdict expected[] = {Verdict::kPass,      Verdict::kImproved, Verdict::kRegressed,
                              Verdict::kRegressed, Verdict::kPass,     Verdict::kRegressed,
                              Verdict::kMissing};
  for (int i = 0; i < 7; ++i) EXPECT_EQ(c[i].verdict, expected[i]) << c[i].metric;
  EXPECT_TRUE(std::isnan(c[6].value));
  const std::string table = FormatComparisons(c);
  EXPECT_NE(table.find("REGRESSED"), std::string::npos);
  EXPECT_NE(ComparisonsToCsv(c).find("s,c,1,0.8,0.1,false,higher,REGRESSED"), std::string::npos);
}

TEST(RegressTest, DefaultMetricsCoverTheStagesPresent) {
  const nlohmann::json metrics = {
      {"takes", {{{"frames", 10}, {"mean_quality", 0.5}, {"tracking", {{"success_rate", 1.0}}}}}},
      {"montage", {{"truth", {{"total_cost", -3.0}}}}}};
  const auto m = DefaultBaselineMetrics(metrics);
  std::vector<std::string> keys;
  for (const auto& [k, t] : m) keys.push_back(k);
  EXPECT_EQ(keys, (std::vector<std::string>{"takes.0.frames", "takes.0.mean_quality",
                                            "takes.0.tracking.success_rate",
                                            "montage.truth.total_cost"}));
}

}  // namespace
}  // namespace mmh::pipeline
