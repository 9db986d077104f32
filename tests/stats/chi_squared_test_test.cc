#include "stats/chi_squared_test.h"

#include <gtest/gtest.h>

#include "tests/stats/golden.h"
#include "tests/test_util.h"

namespace mmh::stats {
namespace {

using golden::Golden;

void ExpectVectorsNearR(const std::vector<double>& actual, const nlohmann::json& expected,
                        const char* what) {
  SCOPED_TRACE(what);
  ASSERT_EQ(actual.size(), expected.size());
  for (std::size_t i = 0; i < actual.size(); ++i) {
    MMH_EXPECT_NEAR_R(actual[i], expected[i].get<double>());
  }
}

void ExpectMatchesR(const ChiSquaredResult& r, const nlohmann::json& c) {
  MMH_EXPECT_NEAR_R(r.statistic, c.at("statistic").get<double>());
  MMH_EXPECT_NEAR_R(r.df, c.at("parameter").get<double>());
  MMH_EXPECT_NEAR_R(r.p_value, c.at("p_value").get<double>());
  ExpectVectorsNearR(r.expected, c.at("expected"), "expected");
  ExpectVectorsNearR(r.residuals, c.at("residuals"), "residuals");
  ExpectVectorsNearR(r.standardized_residuals, c.at("stdres"), "stdres");
}

TEST(ChiSquaredGoodnessOfFit, MatchesRForEveryGoldenCase) {
  int compared = 0;
  for (const auto& c : Golden().at("chisq_gof")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const ChiSquaredResult r =
        ChiSquaredGoodnessOfFit(golden::Vector(c.at("x")), golden::Vector(c.at("p")));
    EXPECT_FALSE(r.yates);  // never a continuity correction for goodness of fit (R)
    ExpectMatchesR(r, c);
    ++compared;
  }
  EXPECT_GE(compared, 4);
}

TEST(ChiSquaredIndependence, MatchesRForEveryGoldenCase) {
  int compared = 0;
  for (const auto& c : Golden().at("chisq_table")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const Eigen::MatrixXd table = golden::Matrix(c.at("table"));
    const ChiSquaredResult r = ChiSquaredIndependence(table, c.at("correct").get<bool>());
    EXPECT_EQ(r.method, c.at("method").get<std::string>());
    ExpectMatchesR(r, c);
    ++compared;
  }
  EXPECT_GE(compared, 5);
}

TEST(ChiSquaredIndependence, YatesOnlyForTwoByTwo) {
  Eigen::MatrixXd t22(2, 2);
  t22 << 12, 5, 7, 16;
  EXPECT_TRUE(ChiSquaredIndependence(t22, true).yates);
  EXPECT_FALSE(ChiSquaredIndependence(t22, false).yates);
  EXPECT_LT(ChiSquaredIndependence(t22, true).statistic,
            ChiSquaredIndependence(t22, false).statistic);
  Eigen::MatrixXd t32(3, 2);
  t32 << 12, 5, 7, 16, 4, 4;
  EXPECT_FALSE(ChiSquaredIndependence(t32, true).yates);
  EXPECT_EQ(ChiSquaredIndependence(t32, true).statistic,
            ChiSquaredIndependence(t32, false).statistic);
}

TEST(ChiSquared, EffectSizes) {
  const std::vector<double> x = {30.0, 10.0};
  const ChiSquaredResult gof = ChiSquaredGoodnessOfFit(x);
  EXPECT_DOUBLE_EQ(gof.statistic, 10.0);  // (10^2 + 10^2) / 20
  EXPECT_DOUBLE_EQ(gof.effect_size, std::sqrt(10.0 / 40.0));
  Eigen::MatrixXd perfect(2, 2);
  perfect << 4, 0, 0, 4;
  // Cramer's V of a perfect association is 1 (from the uncorrected statistic).
  EXPECT_DOUBLE_EQ(ChiSquaredIndependence(perfect, true).effect_size, 1.0);
  EXPECT_TRUE(ChiSquaredIndependence(perfect, true).approximation_warning);
}

TEST(ChiSquared, RejectsBadInput) {
  const std::vector<double> x = {3.0, 4.0};
  const std::vector<double> bad_p = {0.5, 0.6};
  EXPECT_NE(test_util::ErrorOf([&] { ChiSquaredGoodnessOfFit(x, bad_p); }).find("summing to 1"),
            std::string::npos);
  const std::vector<double> negative = {3.0, -1.0};
  EXPECT_NE(test_util::ErrorOf([&] { ChiSquaredGoodnessOfFit(negative); }).find("observed[1]"),
            std::string::npos);
  Eigen::MatrixXd zero_row(2, 2);
  zero_row << 0, 0, 3, 4;
  EXPECT_NE(test_util::ErrorOf([&] { ChiSquaredIndependence(zero_row); }).find("row 0"),
            std::string::npos);
}

}  // namespace
}  // namespace mmh::stats
