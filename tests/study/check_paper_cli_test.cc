// `mmh check-paper` end to end.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/test_util.h"

namespace mmh::study {
namespace {

using test_util::ReadBytes;
using test_util::RunMmh;
using test_util::TempDir;
using test_util::WriteText;

TEST(CheckPaperCommand, PrintsTheTableAndWritesJson) {
  TempDir dir;
  const auto result = RunMmh("check-paper --out '" + (dir / "out").string() + "'");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("INCONSISTENT   h1_t_from_mean_sd_n"), std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("consistent     h3_f_p"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("9 consistent, 3 inconsistent"), std::string::npos);
  const auto json = nlohmann::json::parse(ReadBytes(dir / "out" / "paper_audit.json"));
  EXPECT_EQ(json["inconsistent"], 3);
  EXPECT_EQ(json["checks"].size(), 12u);
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "run.json"));
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "config.resolved.json"));
}

TEST(CheckPaperCommand, BadReportedFileExitsTwo) {
  TempDir dir;
  WriteText(dir / "r.json",
            "{\"checks\": [{\"kind\": \"grim\", \"id\": \"a\", \"section\": \"s\", "
            "\"quote\": \"q\", \"mean\": 0.5, \"denominator\": 4}]}");
  auto result = RunMmh("check-paper --reported '" + (dir / "r.json").string() + "'");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.output.find("checks[0].mean"), std::string::npos) << result.output;
  WriteText(dir / "broken.json", "{\"checks\": [");
  result = RunMmh("check-paper --reported '" + (dir / "broken.json").string() + "'");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.output.find("invalid JSON"), std::string::npos) << result.output;
}

}  // namespace
}  // namespace mmh::study
