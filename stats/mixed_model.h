// The mixed model of hypothesis H3 (paper, "Scorers' perspective"): a score per (animator, take)
// with take as a fixed factor and a random intercept per animator,
//   y = X beta + Z b + e,  b ~ N(0, sigma_a^2 I),  e ~ N(0, sigma^2 I),
// fitted by REML as lme4's lmer(y ~ take + (1 | animator), REML = TRUE), and the F test of the
// take effect with Satterthwaite's denominator degrees of freedom as lmerTest's anova() computes
// it. Balanced or not; for balanced data the repeated-measures ANOVA is reported beside it (the
// two agree unless the animator variance estimate is at its boundary, 0).
//
// Method (docs/statistics.md): V = I + psi Z Z' (psi = theta^2 = sigma_a^2 / sigma^2) is block
// diagonal with closed-form inverse per animator, so the profiled REML criterion and its exact
// derivative in psi cost O(N p^2); the optimum is the root of the derivative (bracketed on a grid,
// refined by bisection to the last bit) or the boundary psi = 0. lmerTest's Hessian of the
// deviance in (theta, sigma) and the Jacobian of vcov(beta), which it approximates numerically,
// are formed analytically here.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "stats/htest.h"

namespace mmh::stats {

struct MixedModelOptions {
  // Eigenvalues of the deviance Hessian below this are treated as zero when it is inverted
  // (lmerTest's tol = 1e-8 in as_lmerModLmerTest).
  double hessian_tolerance = 1e-8;
  // Grid points per decade of psi in [1e-10, 1e10] on which the REML score is bracketed.
  int grid_points_per_decade = 4;
  // Coverage of the fixed effects' confidence intervals (lmerTest's contest1D level).
  double conf_level = 0.95;

  template <class V>
  void VisitFields(V& v) {
    v("hessian_tolerance", hessian_tolerance);
    v("grid_points_per_decade", grid_points_per_decade);
    v("conf_level", conf_level);
  }
  void Validate(const std::string& prefix) const;
};

// An F test of the fixed factor (lmerTest's anova row; a repeated-measures ANOVA row).
struct FTest {
  double f = 0.0;
  double num_df = 0.0;
  double den_df = 0.0;
  double p_value = 0.0;
  double sum_sq = 0.0;   // lmerTest: F sigma^2 num_df; ANOVA: the factor's sum of squares
  double mean_sq = 0.0;  // sum_sq / num_df
  // Partial eta squared from F: F num_df / (F num_df + den_df).
  double partial_eta_squared = 0.0;

  nlohmann::json ToJson() const;
};

// One fixed effect with its Satterthwaite t test and Wald interval (lmerTest's summary() row and
// contest1D(confint = TRUE)).
struct FixedEffect {
  std::string name;  // "(Intercept)", then "take2", "take3", ... (level j + 1 minus level 1)
  double estimate = 0.0;
  double standard_error = 0.0;
  double df = 0.0;
  double t = 0.0;
  double p_value = 0.0;  // two-sided
  ConfidenceInterval conf_int;

  nlohmann::json ToJson() const;
};

struct MixedModelSummary {
  std::size_t observations = 0;  // N
  std::size_t groups = 0;        // animators
  std::size_t levels = 0;        // k, levels of the fixed factor
  bool balanced = false;         // every group has every level exactly once
  int score_evaluations = 0;     // REML score evaluations in the optimisation
  std::vector<std::string> warnings;

  nlohmann::json ToJson() const;
};

struct MixedModelResult {
  // REML estimates. theta = sigma_a / sigma (lme4's theta).
  double theta = 0.0;
  double sigma = 0.0;              // residual standard deviation
  double group_variance = 0.0;     // sigma_a^2
  double residual_variance = 0.0;  // sigma^2
  // Intra-class correlation sigma_a^2 / (sigma_a^2 + sigma^2).
  double icc = 0.0;
  // theta = 0: the REML optimum is on the boundary (lme4: "boundary (singular) fit").
  bool boundary = false;
  // lme4's REMLcrit: -2 times the restricted log-likelihood at the optimum.
  double reml_criterion = 0.0;
  // Fixed effects in treatment coding: (Intercept) = mean of level 0, then level j - level 0.
  Eigen::VectorXd beta;                    // #levels
  Eigen::MatrixXd beta_covariance;         // #levels by #levels (lme4's vcov)
  std::vector<FixedEffect> fixed_effects;  // one per entry of beta, same order
  // lmerTest: the contrast matrix of the test (type I = III for one factor), the per-direction
  // Satterthwaite df and the F test.
  Eigen::MatrixXd contrast;  // (#levels - 1) by #levels
  std::vector<double> direction_df;
  FTest take_test;
  // Conditional modes of the random intercepts (lme4's ranef), per group, and the conditional
  // residuals y - X beta - Z b (lme4's residuals), per observation in input order.
  std::vector<double> random_effects;
  std::vector<double> fitted;
  std::vector<double> residuals;
  // Repeated-measures ANOVA (Error(animator / take)) when the design is balanced, with its
  // df (k - 1, (n - 1)(k - 1)).
  std::optional<FTest> rm_anova;
  // True when rm_anova exists and agrees with take_test (F and df within 1e-8 relative); false
  // at the boundary, where they differ (the Summary says so).
  bool agrees_with_rm_anova = false;
  MixedModelSummary summary;

  nlohmann::json ToJson() const;
};

// Fits y ~ level + (1 | group). `group` and `level` are 0-based indices (each index from 0 to its
// maximum must occur), one entry per observation. Throws InputError for mismatched lengths,
// non-finite scores, fewer than 2 groups or 2 levels, no replication within groups (as many groups
// as observations), or scores the fixed effects fit exactly (residual sum of squares 0).
MixedModelResult FitRandomInterceptModel(std::span<const int> group, std::span<const int> level,
                                         std::span<const double> y,
                                         const MixedModelOptions& options = {});

}  // namespace mmh::stats
