#include "stats/binomial_test.h"

#include <gtest/gtest.h>

#include "tests/stats/golden.h"
#include "tests/test_util.h"

namespace mmh::stats {
namespace {

using golden::Golden;

TEST(BinomialTest, MatchesRForEveryGoldenCase) {
  int compared = 0;
  for (const auto& c : Golden().at("binom")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    BinomialTestOptions options;
    options.p = c.at("p");
    options.conf_level = c.at("conf_level");
    options.alternative = golden::AlternativeNamed(c.at("alternative"));
    const BinomialTestResult r = BinomialTest(c.at("x"), c.at("n"), options);
    MMH_EXPECT_NEAR_R(r.p_value, c.at("p_value").get<double>());
    MMH_EXPECT_NEAR_R(r.estimate, c.at("estimate").get<double>());
    MMH_EXPECT_NEAR_R(r.conf_int.lower, c.at("conf_int")[0].get<double>());
    MMH_EXPECT_NEAR_R(r.conf_int.upper, c.at("conf_int")[1].get<double>());
    ++compared;
  }
  EXPECT_GE(compared, 24);
}

TEST(BinomialTest, TwoSidedRuleIsNotTwiceTheSmallerTailForAsymmetricP) {
  // x = 3 of 20 at p = 0.3 (mean 6): the two-sided p sums the lower tail P(X <= 3) and the upper
  // outcomes no more likely than P(X = 3); doubling the tail would give another value.
  BinomialTestOptions two_sided;
  two_sided.p = 0.3;
  BinomialTestOptions less = two_sided;
  less.alternative = Alternative::kLess;
  const double p2 = BinomialTest(3, 20, two_sided).p_value;
  const double p1 = BinomialTest(3, 20, less).p_value;
  EXPECT_GT(p2, p1);
  EXPECT_GT(std::abs(p2 - 2.0 * p1), 1e-3);
}

TEST(BinomialTest, RejectsBadInput) {
  EXPECT_NE(test_util::ErrorOf([] { BinomialTest(5, 4); }).find("[0, 4]"), std::string::npos);
  EXPECT_NE(test_util::ErrorOf([] { BinomialTest(0, 0); }).find("at least 1 trial"),
            std::string::npos);
  BinomialTestOptions options;
  options.p = 1.5;
  EXPECT_NE(test_util::ErrorOf([&] { BinomialTest(1, 2, options); }).find(".p"), std::string::npos);
}

}  // namespace
}  // namespace mmh::stats
