// Pearson's chi-squared tests as R's chisq.test: goodness of fit to given probabilities (never a
// continuity correction, as in R) and independence in a contingency table (Yates' continuity
// correction for 2x2 tables only, when asked, as R's correct = TRUE).
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

namespace mmh::stats {

struct ChiSquaredResult {
  std::string method;      // as R's method string
  double statistic = 0.0;  // X-squared
  double df = 0.0;
  double p_value = 0.0;  // upper tail of chi-squared(df)
  double total = 0.0;    // sum of the counts (n)
  // Expected counts, Pearson residuals (x - E) / sqrt(E) and standardised residuals (R's stdres),
  // row-major for a table.
  std::vector<double> expected;
  std::vector<double> residuals;
  std::vector<double> standardized_residuals;
  bool yates = false;  // Yates' correction applied (2x2 table, correct = true, |x - E| > 0)
  // Some expected count < 5: R warns "Chi-squared approximation may be incorrect".
  bool approximation_warning = false;
  // Goodness of fit: Cohen's w = sqrt(X^2 / n). Table: Cramer's V = sqrt(X^2 / (n (min(r, c) -
  // 1))) from the uncorrected statistic (an effect size is not continuity-corrected).
  std::string effect_size_name;
  double effect_size = 0.0;

  nlohmann::json ToJson() const;
};

// Goodness of fit of the counts `observed` (non-negative, not all zero, at least 2) to
// `probabilities` (same length, non-negative, summing to 1 within sqrt(eps) as R requires; empty
// means uniform). Throws InputError otherwise, and when an expected count is zero.
ChiSquaredResult ChiSquaredGoodnessOfFit(std::span<const double> observed,
                                         std::span<const double> probabilities = {});

// Independence of rows and columns of a contingency table of non-negative counts (at least 2x2).
// `correct`: Yates' correction, applied only to 2x2 tables (R's correct). Throws InputError when a
// row or column sums to zero (R returns NaN there).
ChiSquaredResult ChiSquaredIndependence(const Eigen::MatrixXd& table, bool correct = true);

}  // namespace mmh::stats
