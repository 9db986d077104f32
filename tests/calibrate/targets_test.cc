// The targets file: the shipped one loads, and every kind of mistake is a clear error.
#include "calibrate/targets.h"

#include <gtest/gtest.h>

#include "tests/test_util.h"

namespace mmh::calibrate {
namespace {

using test_util::ErrorOf;
using test_util::TempDir;
using test_util::WriteText;

TEST(TargetsTest, ThePapersTargetsLoad) {
  const Targets t = LoadTargets(std::string(MMH_SOURCE_DIR) + "/configs/calibration/paper_targets.json");
  ASSERT_GE(t.targets.size(), 8u);
  EXPECT_EQ(t.targets[0].statistic, "friedman_chi_squared");
  EXPECT_EQ(t.targets[0].value, 26.88);
  bool h3_held_out = false;
  for (const Target& target : t.targets) {
    h3_held_out = h3_held_out || (target.statistic == "h3_f" && target.role == TargetRole::kHoldout);
  }
  EXPECT_TRUE(h3_held_out);
  EXPECT_FALSE(t.conclusions.empty());
}

TEST(TargetsTest, MistakesAreErrorsNamingTheEntry) {
  TempDir dir;
  const auto file = dir / "t.json";
  auto error = [&](const std::string& text) {
    WriteText(file, text);
    return ErrorOf([&] { LoadTargets(file); });
  };
  const std::string ok = R"({"statistic": "h1_mean_m", "value": 0.6, "role": "fit"})";
  EXPECT_NE(error(R"({"targets": [{"statistic": "h1_mean", "value": 0.6, "role": "fit"}]})")
                .find("'h1_mean_m'"),
            std::string::npos);
  EXPECT_NE(error(R"({"targets": [{"statistic": "h1_mean_m", "value": 0.6, "role": "fitted"}]})")
                .find("targets[0].role"),
            std::string::npos);
  EXPECT_NE(error(R"({"targets": [{"statistic": "h1_mean_m", "value": 0.6, "role": "fit", "vlue": 1}]})")
                .find("targets[0].vlue"),
            std::string::npos);
  EXPECT_NE(error(R"({"targets": [)" + ok + "," + ok + "]}").find("each statistic once"),
            std::string::npos);
  EXPECT_NE(error(R"({"targets": [{"statistic": "h1_mean_m", "value": 0.6, "role": "holdout"}]})")
                .find("no target with role"),
            std::string::npos);
  EXPECT_NE(error(R"({"targets": []})").find("non-empty array"), std::string::npos);
  EXPECT_NE(error(R"({"targets": [)" + ok +
                  R"(], "conclusions": [{"id": "x", "statistic": "p_h3", "bound": 0.05, "below": true, "role": "fit"}]})")
                .find("conclusions[0].statistic"),
            std::string::npos);
  EXPECT_NE(error("{").find("t.json"), std::string::npos);
}

}  // namespace
}  // namespace mmh::calibrate
