#include "stats/mixed_model.h"

#include <gtest/gtest.h>

#include "stats/shapiro_wilk.h"
#include "tests/stats/golden.h"
#include "tests/test_util.h"

namespace mmh::stats {
namespace {

using golden::Golden;

// lmerTest differentiates numerically (numDeriv), so its Satterthwaite df carry relative errors of
// up to ~5e-11 in the golden cases (38.0000000017 for the exact 38 of a balanced design): R's df
// are compared at 1e-10 like everything else, and the exact df of the balanced cases (aov) at
// 1e-12.
constexpr double kLmerTestDf = 1e-10;
// The intercept's df depend on the between-animator information, where lmerTest's numerical
// Hessian is least accurate: up to 4e-10 relative in the golden cases, while the exact df of the
// balanced cases (below) agree with ours to 1e-14. A p-value far in the tail (1e-21) turns that
// into ~3e-9; the fixed-effect rows are therefore compared with lmerTest at 1e-9 (df, interval)
// and 1e-8 (p), and with the exact R values at 1e-10.
constexpr double kLmerTestFixedEffectDf = 1e-9;
constexpr double kLmerTestFixedEffectP = 1e-8;
// lmer's default optimiser stops with theta known to ~1e-7; its default fit is compared loosely.
constexpr double kLmerDefault = 1e-6;

struct Case {
  std::vector<int> animator;
  std::vector<int> take;
  std::vector<double> y;
};

Case Read(const nlohmann::json& c) {
  Case data;
  data.animator = c.at("animator").get<std::vector<int>>();
  data.take = c.at("take").get<std::vector<int>>();
  data.y = golden::Vector(c.at("y"));
  return data;
}

TEST(RandomInterceptModel, MatchesLmerAndLmerTestForEveryGoldenCase) {
  int compared = 0;
  for (const auto& c : Golden().at("mixed")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const Case data = Read(c);
    const MixedModelResult r = FitRandomInterceptModel(data.animator, data.take, data.y);
    EXPECT_EQ(r.boundary, c.at("singular").get<bool>());
    EXPECT_EQ(r.summary.balanced, c.at("balanced").get<bool>());
    const double theta = c.at("theta");
    if (theta == 0.0) {
      EXPECT_EQ(r.theta, 0.0);
    } else {
      MMH_EXPECT_NEAR_R(r.theta, theta);
    }
    MMH_EXPECT_NEAR_R(r.sigma, c.at("sigma").get<double>());
    MMH_EXPECT_NEAR_R(r.reml_criterion, c.at("reml_criterion").get<double>());
    const std::vector<double> beta = golden::Vector(c.at("beta"));
    ASSERT_EQ(static_cast<std::size_t>(r.beta.size()), beta.size());
    for (std::size_t i = 0; i < beta.size(); ++i) MMH_EXPECT_NEAR_R(r.beta(i), beta[i]);
    const Eigen::MatrixXd vcov = golden::Matrix(c.at("vcov"));
    for (Eigen::Index i = 0; i < vcov.rows(); ++i) {
      for (Eigen::Index j = 0; j < vcov.cols(); ++j) {
        MMH_EXPECT_NEAR_R(r.beta_covariance(i, j), vcov(i, j));
      }
    }
    const auto& coefficients = c.at("coefficients");
    ASSERT_EQ(r.fixed_effects.size(), coefficients.size());
    for (std::size_t i = 0; i < coefficients.size(); ++i) {
      const auto& e = coefficients[i];
      const FixedEffect& f = r.fixed_effects[i];
      MMH_EXPECT_NEAR_R(f.estimate, e.at("estimate").get<double>());
      MMH_EXPECT_NEAR_R(f.standard_error, e.at("standard_error").get<double>());
      MMH_EXPECT_NEAR_R(f.t, e.at("t").get<double>());
      MMH_EXPECT_NEAR_R(f.df, e.at("df").get<double>(), kLmerTestFixedEffectDf);
      MMH_EXPECT_NEAR_R(f.p_value, e.at("p_value").get<double>(), kLmerTestFixedEffectP);
      MMH_EXPECT_NEAR_R(f.conf_int.lower, e.at("lower").get<double>(), kLmerTestFixedEffectDf);
      MMH_EXPECT_NEAR_R(f.conf_int.upper, e.at("upper").get<double>(), kLmerTestFixedEffectDf);
    }
    if (!c.at("intercept_exact").is_null()) {
      // The exact df of the intercept (classic Satterthwaite from aov's mean squares, in R).
      const auto& e = c.at("intercept_exact");
      const FixedEffect& f = r.fixed_effects[0];
      MMH_EXPECT_NEAR_R(f.df, e.at("df").get<double>(), 1e-12);
      MMH_EXPECT_NEAR_R(f.p_value, e.at("p_value").get<double>());
      MMH_EXPECT_NEAR_R(f.conf_int.lower, e.at("lower").get<double>());
      MMH_EXPECT_NEAR_R(f.conf_int.upper, e.at("upper").get<double>());
    }
    const auto& anova = c.at("anova");
    MMH_EXPECT_NEAR_R(r.take_test.f, anova.at("f").get<double>());
    MMH_EXPECT_NEAR_R(r.take_test.num_df, anova.at("num_df").get<double>());
    MMH_EXPECT_NEAR_R(r.take_test.den_df, anova.at("den_df").get<double>(), kLmerTestDf);
    MMH_EXPECT_NEAR_R(r.take_test.p_value, anova.at("p_value").get<double>());
    MMH_EXPECT_NEAR_R(r.take_test.sum_sq, anova.at("sum_sq").get<double>());
    MMH_EXPECT_NEAR_R(r.take_test.mean_sq, anova.at("mean_sq").get<double>());
    // lmer with its default optimiser, as a user would run it.
    const auto& anova_default = c.at("anova_default");
    MMH_EXPECT_NEAR_R(r.take_test.f, anova_default.at("f").get<double>(), kLmerDefault);
    MMH_EXPECT_NEAR_R(r.take_test.den_df, anova_default.at("den_df").get<double>(), kLmerDefault);
    MMH_EXPECT_NEAR_R(r.take_test.p_value, anova_default.at("p_value").get<double>(), kLmerDefault);

    // Conditional modes and residuals: compared relative to their largest magnitude (single
    // entries can be near zero).
    const std::vector<double> ranef = golden::Vector(c.at("ranef"));
    const std::vector<double> residuals = golden::Vector(c.at("residuals"));
    ASSERT_EQ(r.random_effects.size(), ranef.size());
    ASSERT_EQ(r.residuals.size(), residuals.size());
    double ranef_scale = 1e-300;
    double residual_scale = 1e-300;
    for (double v : ranef) ranef_scale = std::max(ranef_scale, std::abs(v));
    for (double v : residuals) residual_scale = std::max(residual_scale, std::abs(v));
    for (std::size_t i = 0; i < ranef.size(); ++i) {
      EXPECT_NEAR(r.random_effects[i], ranef[i], golden::kRelative * ranef_scale) << i;
    }
    for (std::size_t i = 0; i < residuals.size(); ++i) {
      EXPECT_NEAR(r.residuals[i], residuals[i], golden::kRelative * residual_scale) << i;
    }
    const ShapiroWilkResult sw = ShapiroWilkTest(r.residuals);
    MMH_EXPECT_NEAR_R(sw.w, c.at("residual_shapiro").at("w").get<double>());
    MMH_EXPECT_NEAR_R(sw.p_value, c.at("residual_shapiro").at("p_value").get<double>());

    // Balanced: the repeated-measures ANOVA (aov, Error(animator / take)) is exact in R too.
    const auto& rm = c.at("rm_anova");
    ASSERT_EQ(r.rm_anova.has_value(), !rm.is_null());
    if (r.rm_anova) {
      MMH_EXPECT_NEAR_R(r.rm_anova->f, rm.at("f").get<double>());
      MMH_EXPECT_NEAR_R(r.rm_anova->den_df, rm.at("den_df").get<double>());
      MMH_EXPECT_NEAR_R(r.rm_anova->p_value, rm.at("p_value").get<double>());
      MMH_EXPECT_NEAR_R(r.rm_anova->sum_sq, rm.at("sum_sq").get<double>());
      if (r.boundary) {
        // At the boundary the mixed model is OLS: F and df differ, and the result says so.
        EXPECT_FALSE(r.agrees_with_rm_anova);
        EXPECT_GT(std::abs(r.take_test.den_df - r.rm_anova->den_df), 1.0);
      } else {
        EXPECT_TRUE(r.agrees_with_rm_anova);
        MMH_EXPECT_NEAR_R(r.take_test.f, rm.at("f").get<double>());
        MMH_EXPECT_NEAR_R(r.take_test.den_df, rm.at("den_df").get<double>(), 1e-12);
      }
    }
    if (r.boundary) {
      bool warned = false;
      for (const auto& w : r.summary.warnings)
        warned = warned || w.find("boundary") != std::string::npos;
      EXPECT_TRUE(warned);
    }
    ++compared;
  }
  EXPECT_GE(compared, 7);
}

TEST(RandomInterceptModel, BoundaryDfIsTheResidualDfOfLeastSquares) {
  // Within-animator noise larger than the between-animator spread: sigma_a^2 = 0, and the F test
  // is the one-way ANOVA of ordinary least squares with N - k denominator df.
  const std::vector<int> animator = {0, 0, 0, 1, 1, 1, 2, 2, 2};
  const std::vector<int> take = {0, 1, 2, 0, 1, 2, 0, 1, 2};
  const std::vector<double> y = {1.0, 3.0, 2.0, 3.0, 1.0, 2.5, 2.0, 2.0, 1.0};
  const MixedModelResult r = FitRandomInterceptModel(animator, take, y);
  ASSERT_TRUE(r.boundary);
  EXPECT_NEAR(r.take_test.den_df, 6.0, 1e-12);
  ASSERT_TRUE(r.rm_anova.has_value());
  EXPECT_EQ(r.rm_anova->den_df, 4.0);
  EXPECT_FALSE(r.agrees_with_rm_anova);
}

TEST(RandomInterceptModel, RejectsDegenerateData) {
  const std::vector<int> animator = {0, 0, 1, 1};
  const std::vector<int> take = {0, 1, 0, 1};
  const std::vector<double> constant = {0.5, 0.5, 0.5, 0.5};
  EXPECT_NE(test_util::ErrorOf([&] {
              FitRandomInterceptModel(animator, take, constant);
            }).find("fit exactly"),
            std::string::npos);
  const std::vector<double> y = {0.1, 0.5, 0.3};
  EXPECT_NE(test_util::ErrorOf([&] {
              FitRandomInterceptModel(animator, take, y);
            }).find("one group and one level index per score"),
            std::string::npos);
  const std::vector<int> one_each = {0, 1};
  const std::vector<int> take2 = {0, 1};
  const std::vector<double> y2 = {0.1, 0.5};
  EXPECT_NE(test_util::ErrorOf([&] {
              FitRandomInterceptModel(one_each, take2, y2);
            }).find("more observations than groups"),
            std::string::npos);
}

}  // namespace
}  // namespace mmh::stats
