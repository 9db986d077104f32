#include "stats/shapiro_wilk.h"

#include <gtest/gtest.h>

#include "tests/stats/golden.h"
#include "tests/test_util.h"

namespace mmh::stats {
namespace {

using golden::Golden;

TEST(ShapiroWilkTest, MatchesRForEveryGoldenCase) {
  int compared = 0;
  for (const auto& c : Golden().at("shapiro")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const std::vector<double> x = golden::Vector(c.at("x"));
    if (c.contains("error")) {
      EXPECT_NE(test_util::ErrorOf([&] { ShapiroWilkTest(x); }).find("identical"),
                std::string::npos);
      continue;
    }
    const ShapiroWilkResult r = ShapiroWilkTest(x);
    MMH_EXPECT_NEAR_R(r.w, c.at("w").get<double>());
    MMH_EXPECT_NEAR_R(r.p_value, c.at("p_value").get<double>());
    ++compared;
  }
  EXPECT_GE(compared, 13);
}

TEST(ShapiroWilkTest, OrderDoesNotMatter) {
  const std::vector<double> a = {2.1, 3.4, 1.9, 7.5, 0.3};
  const std::vector<double> b = {7.5, 0.3, 3.4, 2.1, 1.9};
  EXPECT_EQ(ShapiroWilkTest(a).w, ShapiroWilkTest(b).w);
  EXPECT_EQ(ShapiroWilkTest(a).p_value, ShapiroWilkTest(b).p_value);
}

TEST(ShapiroWilkTest, RejectsSampleSizesOutsideAlgorithmRange) {
  const std::vector<double> two = {1.0, 2.0};
  EXPECT_NE(test_util::ErrorOf([&] { ShapiroWilkTest(two); }).find("between 3 and 5000"),
            std::string::npos);
  const std::vector<double> many(5001, 1.0);
  EXPECT_NE(test_util::ErrorOf([&] { ShapiroWilkTest(many); }).find("between 3 and 5000"),
            std::string::npos);
}

}  // namespace
}  // namespace mmh::stats
