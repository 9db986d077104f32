#include "stats/t_test.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/options.h"
#include "tests/stats/golden.h"
#include "tests/test_util.h"

namespace mmh::stats {
namespace {

using golden::Golden;
using golden::Number;

TEST(OneSampleTTest, MatchesRForEveryGoldenCase) {
  int compared = 0;
  for (const auto& c : Golden().at("t_test")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const std::vector<double> x = golden::Vector(c.at("x"));
    TTestOptions options;
    options.mu = c.at("mu");
    options.alternative = golden::AlternativeNamed(c.at("alternative"));
    options.conf_level = c.at("conf_level");
    if (c.contains("error")) {
      // R refuses (constant data): so do we, with R's reason in the message.
      EXPECT_NE(test_util::ErrorOf([&] { OneSampleTTest(x, options); }).find("constant"),
                std::string::npos);
      continue;
    }
    const TTestResult r = OneSampleTTest(x, options);
    MMH_EXPECT_NEAR_R(r.t, c.at("statistic").get<double>());
    MMH_EXPECT_NEAR_R(r.df, c.at("parameter").get<double>());
    MMH_EXPECT_NEAR_R(r.p_value, c.at("p_value").get<double>());
    MMH_EXPECT_NEAR_R(r.mean, c.at("estimate").get<double>());
    MMH_EXPECT_NEAR_R(r.standard_error, c.at("stderr").get<double>());
    MMH_EXPECT_NEAR_R(r.conf_int.lower, Number(c.at("conf_int")[0], -1.0));
    MMH_EXPECT_NEAR_R(r.conf_int.upper, Number(c.at("conf_int")[1], 1.0));
    ++compared;
  }
  EXPECT_GE(compared, 21);
}

TEST(OneSampleTTest, EffectSizeAndJson) {
  const std::vector<double> x = {1.0, 2.0, 3.0, 4.0};
  TTestOptions options;
  options.mu = 1.0;
  options.alternative = Alternative::kGreater;
  const TTestResult r = OneSampleTTest(x, options);
  EXPECT_DOUBLE_EQ(r.cohens_d, (2.5 - 1.0) / r.sd);
  const nlohmann::json j = r.ToJson();
  EXPECT_TRUE(j["conf_int"]["upper"].is_null());  // one-sided: +Inf
  EXPECT_EQ(j["alternative"], "greater");
}

TEST(OneSampleTTest, RejectsBadInput) {
  const std::vector<double> one = {1.0};
  EXPECT_NE(test_util::ErrorOf([&] { OneSampleTTest(one); }).find("at least 2 values"),
            std::string::npos);
  const std::vector<double> nan = {1.0, std::nan(""), 2.0};
  EXPECT_NE(test_util::ErrorOf([&] { OneSampleTTest(nan); }).find("t-test sample[1]"),
            std::string::npos);
  TTestOptions options;
  options.conf_level = 1.0;
  const std::vector<double> x = {1.0, 2.0};
  EXPECT_NE(test_util::ErrorOf([&] { OneSampleTTest(x, options); }).find("conf_level"),
            std::string::npos);
}

TEST(OneSampleTTest, OptionsFromJsonRejectUnknownAlternative) {
  TTestOptions options;
  const std::string message = test_util::ErrorOf([&] {
    FromJson(nlohmann::json{{"alternative", "greatr"}}, "h1", ConfigSource{"test"}, &options);
  });
  EXPECT_NE(message.find("two.sided"), std::string::npos) << message;
}

}  // namespace
}  // namespace mmh::stats
