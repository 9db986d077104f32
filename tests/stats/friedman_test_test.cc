#include "stats/friedman_test.h"

#include <gtest/gtest.h>

#include "tests/stats/golden.h"
#include "tests/test_util.h"

namespace mmh::stats {
namespace {

using golden::Golden;

TEST(FriedmanTest, MatchesRForEveryGoldenCase) {
  int compared = 0;
  for (const auto& c : Golden().at("friedman")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const Eigen::MatrixXd y = golden::Matrix(c.at("y"));
    if (c.contains("error")) {
      // R: NaN (every block all ties). We refuse with the reason.
      EXPECT_NE(test_util::ErrorOf([&] { FriedmanTest(y); }).find("all ties"), std::string::npos);
      continue;
    }
    const FriedmanResult r = FriedmanTest(y);
    MMH_EXPECT_NEAR_R(r.statistic, c.at("statistic").get<double>());
    MMH_EXPECT_NEAR_R(r.df, c.at("parameter").get<double>());
    MMH_EXPECT_NEAR_R(r.p_value, c.at("p_value").get<double>());
    ++compared;
  }
  EXPECT_GE(compared, 6);
}

TEST(FriedmanTest, RankSumsTiesAndKendallsW) {
  // Two blocks; the second has a tie (ranks 1.5, 1.5, 3): tie sum 2^3 - 2 = 6.
  Eigen::MatrixXd y(2, 3);
  y << 3, 1, 2, 5, 5, 9;
  const FriedmanResult r = FriedmanTest(y);
  EXPECT_EQ(r.rank_sums, (std::vector<double>{4.5, 2.5, 5.0}));
  EXPECT_EQ(r.mean_ranks, (std::vector<double>{2.25, 1.25, 2.5}));
  EXPECT_DOUBLE_EQ(r.tie_sum, 6.0);
  // 12 ((4.5-4)^2 + (2.5-4)^2 + 1^2) / (2*3*4 - 6/2) = 12 * 3.5 / 21 = 2.
  EXPECT_DOUBLE_EQ(r.statistic, 2.0);
  EXPECT_DOUBLE_EQ(r.kendalls_w, 2.0 / (2.0 * 2.0));
}

TEST(FriedmanTest, PerfectAgreementGivesKendallsWOne) {
  Eigen::MatrixXd y(5, 4);
  for (int i = 0; i < 5; ++i) y.row(i) << 1, 2, 3, 4;
  EXPECT_DOUBLE_EQ(FriedmanTest(y).kendalls_w, 1.0);
}

TEST(FriedmanTest, RejectsBadShapesAndValues) {
  EXPECT_NE(test_util::ErrorOf([] { FriedmanTest(Eigen::MatrixXd(3, 1)); }).find("2 groups"),
            std::string::npos);
  Eigen::MatrixXd y(2, 2);
  y << 1, std::nan(""), 2, 1;
  EXPECT_NE(test_util::ErrorOf([&] { FriedmanTest(y); }).find("finite"), std::string::npos);
}

}  // namespace
}  // namespace mmh::stats
