// `mmh stats` end to end: the example study, determinism, and bad CSVs (exit 2, a message naming
// the file, line, column, value and expectation, no output written).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "study/study_analysis.h"
#include "tests/test_util.h"

namespace mmh::study {
namespace {

using test_util::ReadBytes;
using test_util::RunMmh;
using test_util::TempDir;
using test_util::WriteText;

const std::filesystem::path kExample =
    std::filesystem::path(MMH_SOURCE_DIR) / "examples" / "study_data";

TEST(StatsCommand, ExampleWritesEveryOutputAndMatchesTheLibrary) {
  TempDir dir;
  const auto result =
      RunMmh("stats --input '" + kExample.string() + "' --out '" + (dir / "out").string() + "'");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("rankings: Friedman chi2(df = 3, N = 20)"), std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("H3: mixed model F(2, 38)"), std::string::npos) << result.output;
  for (const char* file : {"results.json", "tests.csv", "take_scores.csv", "animator_scores.csv",
                           "mean_ranks.csv", "report.txt", "config.resolved.json", "run.json"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / file)) << file;
  }
  const StudyAnalysis expected = AnalyzeStudy(ReadStudyData(kExample));
  EXPECT_EQ(ReadBytes(dir / "out" / "results.json"), expected.ToJson().dump(2) + "\n");
  EXPECT_EQ(ReadBytes(dir / "out" / "tests.csv"), expected.TestsCsv());
  const auto resolved = nlohmann::json::parse(ReadBytes(dir / "out" / "config.resolved.json"));
  EXPECT_EQ(resolved["stats"]["chance"], 0.5);
  EXPECT_EQ(resolved["stats"]["alternative"], "greater");
  const auto run = nlohmann::json::parse(ReadBytes(dir / "out" / "run.json"));
  EXPECT_TRUE(run.contains("git_commit"));
}

TEST(StatsCommand, SameInputSameBytes) {
  TempDir dir;
  const std::string base = "stats --quiet --input '" + kExample.string() + "' --out '";
  ASSERT_EQ(RunMmh(base + (dir / "a").string() + "'").exit_code, 0);
  ASSERT_EQ(RunMmh(base + (dir / "b").string() + "' --set stats.h1_unit=take_scores").exit_code, 0);
  ASSERT_EQ(RunMmh(base + (dir / "c").string() + "'").exit_code, 0);
  EXPECT_EQ(ReadBytes(dir / "a" / "results.json"), ReadBytes(dir / "c" / "results.json"));
  EXPECT_NE(ReadBytes(dir / "a" / "results.json"), ReadBytes(dir / "b" / "results.json"));
  // t over the 60 m_ij: df 59.
  const auto b = nlohmann::json::parse(ReadBytes(dir / "b" / "results.json"));
  EXPECT_EQ(b["h1"]["t_test"]["df"], 59.0);
}

TEST(StatsCommand, BadCsvExitsTwoNamingFileLineColumnValueAndWritesNothing) {
  TempDir dir;
  std::filesystem::copy(kExample, dir / "in");
  std::string rankings = ReadBytes(dir / "in" / "rankings.csv");
  rankings.replace(rankings.find("A01,take2,2"), 11, "A01,take2,4");
  WriteText(dir / "in" / "rankings.csv", rankings);
  const auto result = RunMmh("stats --input '" + (dir / "in").string() + "' --out '" +
                             (dir / "out").string() + "'");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  for (const char* part :
       {"rankings.csv:2", "column 'rank'", "ranks 4, 4, 3, 1", "a permutation of 1..4"}) {
    EXPECT_NE(result.output.find(part), std::string::npos) << part << " in " << result.output;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(StatsCommand, BadConfigKeyAndMissingInput) {
  TempDir dir;
  auto result = RunMmh("stats --input '" + kExample.string() + "' --out '" +
                       (dir / "out").string() + "' --set stats.chanse=0.4");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.output.find("did you mean 'chance'"), std::string::npos) << result.output;
  result = RunMmh("stats --input '" + (dir / "missing").string() + "' --out '" +
                  (dir / "out").string() + "'");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.output.find("missing"), std::string::npos) << result.output;
}

}  // namespace
}  // namespace mmh::study
