// The sweep spec: structure errors name the file, the axis and the value; ranges and samples.
#include "sweep/spec.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "sweep/plan.h"
#include "tests/test_util.h"

namespace mmh::sweep {
namespace {

using nlohmann::json;
using test_util::ErrorOf;

json Minimal() {
  return json::parse(R"({
    "command": "compose",
    "axes": [{"key": "montage.labelling.mu", "values": [10, 100]}],
    "metrics": [{"name": "cost", "file": "summary.json", "key": "total_cost"}]
  })");
}

TEST(SweepSpecTest, ReadsAMinimalSpec) {
  const SweepSpec spec = ParseSpec(Minimal(), "s.json");
  EXPECT_EQ(spec.command, SweepCommand::kCompose);
  ASSERT_EQ(spec.grid.size(), 1u);
  EXPECT_EQ(spec.grid[0].values.size(), 2u);
  EXPECT_EQ(spec.replicates.count, 1);
  ASSERT_EQ(spec.metrics.size(), 1u);
  EXPECT_EQ(spec.metrics[0].statistics.size(), 3u);
}

TEST(SweepSpecTest, UnknownKeyNamesFileAndSuggestion) {
  json j = Minimal();
  j["axis"] = json::array();
  const std::string e = ErrorOf([&] { ParseSpec(j, "configs/sweeps/x.json"); });
  EXPECT_NE(e.find("configs/sweeps/x.json"), std::string::npos) << e;
  EXPECT_NE(e.find("'axis' is unknown"), std::string::npos) << e;
  EXPECT_NE(e.find("did you mean 'axes'"), std::string::npos) << e;
  j = Minimal();
  j["axes"][0]["valeus"] = json::array({1});
  const std::string e2 = ErrorOf([&] { ParseSpec(j, "x.json"); });
  EXPECT_NE(e2.find("'axes[0].valeus' is unknown"), std::string::npos) << e2;
  EXPECT_NE(e2.find("did you mean 'values'"), std::string::npos) << e2;
}

TEST(SweepSpecTest, EmptyAxesAndZeroSamplesAreErrors) {
  json j = Minimal();
  j["axes"][0]["values"] = json::array();
  std::string e = ErrorOf([&] { ParseSpec(j, "x.json"); });
  EXPECT_NE(e.find("axes[0] (montage.labelling.mu).values"), std::string::npos) << e;
  EXPECT_NE(e.find("non-empty"), std::string::npos) << e;
  j = Minimal();
  j["axes"] = json::array();
  e = ErrorOf([&] { ParseSpec(j, "x.json"); });
  EXPECT_NE(e.find("at least one axis"), std::string::npos) << e;
  j = Minimal();
  j["samples"] = {{"count", 0}, {"axes", {{{"key", "montage.reaction_time"}, {"from", 0}, {"to", 1}}}}};
  e = ErrorOf([&] { ParseSpec(j, "x.json"); });
  EXPECT_NE(e.find("samples.count"), std::string::npos) << e;
  EXPECT_NE(e.find("got 0"), std::string::npos) << e;
  j = Minimal();
  j["axes"][0] = {{"key", "montage.labelling.mu"}, {"log", {{"from", 0}, {"to", 10}, {"count", 3}}}};
  e = ErrorOf([&] { ParseSpec(j, "x.json"); });
  EXPECT_NE(e.find("axes[0] (montage.labelling.mu).log.from"), std::string::npos) << e;
}

TEST(SweepSpecTest, ReplicatesNeedASeedForCommandsWithoutOne) {
  json j = Minimal();
  j["replicates"] = {{"count", 3}};
  const std::string e = ErrorOf([&] { ParseSpec(j, "x.json"); });
  EXPECT_NE(e.find("replicates.count"), std::string::npos) << e;
  j["command"] = "run";
  EXPECT_EQ(ParseSpec(j, "x.json").replicates.seed_keys,
            std::vector<std::string>{"population.seed"});
}

TEST(SweepSpecTest, StudyReplicatesDrawNewPeopleAndNewScorers) {
  // A study's replicate seeds both its people and its scorers by default (as
  // StudyConfig::ForReplicate): cells that kept study.seed would share the scorers' design,
  // tastes and judgement noise, and with it any take-order effect that draw carries.
  json j = Minimal();
  j["command"] = "study";
  j["replicates"] = {{"count", 3}};
  EXPECT_EQ(ParseSpec(j, "x.json").replicates.seed_keys,
            (std::vector<std::string>{"population.seed", "study.seed"}));
  // Named keys: one, or a list; nothing else.
  j["replicates"]["seed_key"] = "population.seed";
  EXPECT_EQ(ParseSpec(j, "x.json").replicates.seed_keys,
            std::vector<std::string>{"population.seed"});
  j["replicates"]["seed_key"] = json::array({"study.seed", "population.seed"});
  EXPECT_EQ(ParseSpec(j, "x.json").replicates.seed_keys,
            (std::vector<std::string>{"study.seed", "population.seed"}));
  for (const json& bad : {json::array(), json(3), json::array({"study.seed", ""}), json("")}) {
    j["replicates"]["seed_key"] = bad;
    const std::string e = ErrorOf([&] { ParseSpec(j, "x.json"); });
    EXPECT_NE(e.find("x.json: replicates.seed_key"), std::string::npos) << e;
    EXPECT_NE(e.find("a config key or a non-empty list of config keys"), std::string::npos) << e;
  }
  // An axis on a seeded key would be overwritten in every cell: an error naming both.
  j["replicates"].erase("seed_key");
  j["axes"] = json::array({{{"key", "study.seed"}, {"values", {1, 2}}}});
  std::string e = ErrorOf([&] { ParseSpec(j, "x.json"); });
  EXPECT_NE(e.find("replicates.seed_key"), std::string::npos) << e;
  EXPECT_NE(e.find("each config key on one axis only"), std::string::npos) << e;
  // Also with one replicate: each cell still gets its own seed (per_cell).
  j["replicates"] = {{"count", 1}};
  e = ErrorOf([&] { ParseSpec(j, "x.json"); });
  EXPECT_NE(e.find("each config key on one axis only"), std::string::npos) << e;
  // With common seeds and one replicate nothing is seeded, so the axis may set it.
  j["replicates"] = {{"count", 1}, {"seeds", "common"}};
  EXPECT_FALSE(Seeded(ParseSpec(j, "x.json").replicates));
}

TEST(SweepSpecTest, RangesHitBothEndsExactly) {
  const auto lin = ExpandRange(0.0, 0.6, 4, AxisScale::kLinear);
  ASSERT_EQ(lin.size(), 4u);
  EXPECT_DOUBLE_EQ(lin[1], 0.2);
  EXPECT_EQ(lin.back(), 0.6);
  const auto log = ExpandRange(10.0, 1000.0, 3, AxisScale::kLog);
  EXPECT_DOUBLE_EQ(log[1], 100.0);
  EXPECT_EQ(log.back(), 1000.0);
  // Integer log ranges drop the repeated small values.
  json j = Minimal();
  j["axes"][0] = {{"key", "montage.labelling.min_segment_length"},
                  {"log", {{"from", 1}, {"to", 4}, {"count", 6}}},
                  {"integer", true}};
  const SweepSpec spec = ParseSpec(j, "x.json");
  std::vector<long long> values;
  for (const auto& v : spec.grid[0].values) values.push_back(v.get<long long>());
  EXPECT_EQ(values, (std::vector<long long>{1, 2, 3, 4}));
}

TEST(SweepSpecTest, LatinHypercubeHasOneSampleInEveryStratumOfEveryAxis) {
  SampleSet set;
  set.count = 37;
  set.seed = 11;
  set.axes = {{"a", 0.0, 1.0}, {"b", 2.0, 4.0}, {"c", 1.0, 100.0, AxisScale::kLog}};
  const auto points = SamplePoints(set);
  ASSERT_EQ(points.size(), 37u);
  for (std::size_t a = 0; a < set.axes.size(); ++a) {
    std::set<int> strata;
    for (const auto& p : points) {
      const auto& axis = set.axes[a];
      const double u = axis.scale == AxisScale::kLog
                           ? std::log(p[a] / axis.from) / std::log(axis.to / axis.from)
                           : (p[a] - axis.from) / (axis.to - axis.from);
      ASSERT_GE(u, 0.0);
      ASSERT_LT(u, 1.0);
      strata.insert(static_cast<int>(u * set.count));
    }
    EXPECT_EQ(strata.size(), 37u) << "axis " << a;
  }
  // Same seed, same samples; another seed, others.
  EXPECT_EQ(SamplePoints(set), points);
  set.seed = 12;
  EXPECT_NE(SamplePoints(set), points);
}

TEST(SweepSpecTest, DerivedSeedsDifferPerCellUnlessCommon) {
  Replicates r;
  r.seed = 5;
  EXPECT_NE(DeriveSeed(r, "[1]", 0), DeriveSeed(r, "[2]", 0));
  EXPECT_NE(DeriveSeed(r, "[1]", 0), DeriveSeed(r, "[1]", 1));
  EXPECT_EQ(DeriveSeed(r, "[1]", 0), DeriveSeed(r, "[1]", 0));
  r.scheme = SeedScheme::kCommon;
  EXPECT_EQ(DeriveSeed(r, "[1]", 1), DeriveSeed(r, "[2]", 1));
  EXPECT_LT(DeriveSeed(r, "[1]", 1), 1ull << 31);
}

TEST(SweepSpecTest, EachSeedKeyGetsItsOwnSeedTheFirstTheDerivedOne) {
  std::set<std::uint64_t> seen;
  for (std::uint64_t seed : {0ull, 1ull, 889105769ull, (1ull << 31) - 1}) {
    EXPECT_EQ(ReplicateKeySeed(seed, 0), seed);
    for (std::size_t k = 1; k < 4; ++k) {
      const std::uint64_t s = ReplicateKeySeed(seed, k);
      EXPECT_LT(s, 1ull << 31);
      EXPECT_NE(s, seed);
      EXPECT_TRUE(seen.insert(s).second) << seed << " " << k;
    }
  }
}

}  // namespace
}  // namespace mmh::sweep
