#include "stats/chi_squared_test.h"

#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "stats/htest.h"

namespace mmh::stats {
namespace {

double UpperTail(double statistic, double df) {
  return boost::math::cdf(
      boost::math::complement(boost::math::chi_squared_distribution<double>(df), statistic));
}

void RequireCounts(std::span<const double> counts, const std::string& where) {
  for (std::size_t i = 0; i < counts.size(); ++i) {
    if (!std::isfinite(counts[i]) || counts[i] < 0.0) {
      ThrowBadValue(where + "[" + std::to_string(i) + "]", FormatNumber(counts[i]),
                    "a finite count >= 0");
    }
  }
}

}  // namespace

nlohmann::json ChiSquaredResult::ToJson() const {
  return {{"test", method},
          {"statistic", statistic},
          {"df", df},
          {"p_value", p_value},
          {"total", total},
          {"expected", expected},
          {"residuals", residuals},
          {"standardized_residuals", standardized_residuals},
          {"yates", yates},
          {"approximation_warning", approximation_warning},
          {"effect_size_name", effect_size_name},
          {"effect_size", effect_size}};
}

ChiSquaredResult ChiSquaredGoodnessOfFit(std::span<const double> observed,
                                         std::span<const double> probabilities) {
  const std::size_t k = observed.size();
  if (k < 2) {
    ThrowBadValue("chi-squared goodness of fit", std::to_string(k) + " categories",
                  "at least 2 categories");
  }
  RequireCounts(observed, "chi-squared observed");
  std::vector<double> p(probabilities.begin(), probabilities.end());
  if (p.empty()) p.assign(k, 1.0 / static_cast<double>(k));
  if (p.size() != k) {
    ThrowBadValue("chi-squared probabilities", std::to_string(p.size()) + " values",
                  std::to_string(k) + " (one per category)");
  }
  double p_sum = 0.0;
  for (std::size_t i = 0; i < k; ++i) {
    if (!std::isfinite(p[i]) || p[i] < 0.0) {
      ThrowBadValue("chi-squared probabilities[" + std::to_string(i) + "]", FormatNumber(p[i]),
                    "a probability >= 0");
    }
    p_sum += p[i];
  }
  if (std::abs(p_sum - 1.0) > std::sqrt(std::numeric_limits<double>::epsilon())) {
    ThrowBadValue("chi-squared probabilities", "a sum of " + FormatNumber(p_sum),
                  "probabilities summing to 1");
  }
  ChiSquaredResult r;
  r.method = "Chi-squared test for given probabilities";
  for (double x : observed) r.total += x;
  if (!(r.total > 0.0)) {
    ThrowBadValue("chi-squared observed", "all zero", "at least one positive count");
  }
  for (std::size_t i = 0; i < k; ++i) {
    const double e = r.total * p[i];
    if (!(e > 0.0)) {
      ThrowBadValue("chi-squared probabilities[" + std::to_string(i) + "]", FormatNumber(p[i]),
                    "a probability > 0 (an expected count of 0 makes the statistic undefined)");
    }
    const double d = observed[i] - e;
    r.expected.push_back(e);
    r.statistic += d * d / e;
    r.residuals.push_back(d / std::sqrt(e));
    r.standardized_residuals.push_back(d / std::sqrt(r.total * p[i] * (1.0 - p[i])));
    r.approximation_warning = r.approximation_warning || e < 5.0;
  }
  r.df = static_cast<double>(k - 1);
  r.p_value = UpperTail(r.statistic, r.df);
  r.effect_size_name = "cohens_w";
  r.effect_size = std::sqrt(r.statistic / r.total);
  return r;
}

ChiSquaredResult ChiSquaredIndependence(const Eigen::MatrixXd& table, bool correct) {
  const Eigen::Index rows = table.rows();
  const Eigen::Index cols = table.cols();
  if (rows < 2 || cols < 2) {
    ThrowBadValue("chi-squared table", std::to_string(rows) + "x" + std::to_string(cols),
                  "at least 2x2");
  }
  for (Eigen::Index i = 0; i < rows; ++i) {
    for (Eigen::Index j = 0; j < cols; ++j) {
      if (!std::isfinite(table(i, j)) || table(i, j) < 0.0) {
        ThrowBadValue("chi-squared table(" + std::to_string(i) + ", " + std::to_string(j) + ")",
                      FormatNumber(table(i, j)), "a finite count >= 0");
      }
    }
  }
  const Eigen::VectorXd row_sums = table.rowwise().sum();
  const Eigen::RowVectorXd col_sums = table.colwise().sum();
  ChiSquaredResult r;
  r.total = table.sum();
  for (Eigen::Index i = 0; i < rows; ++i) {
    if (!(row_sums(i) > 0.0)) {
      ThrowBadValue("chi-squared table row " + std::to_string(i), "a sum of 0",
                    "rows and columns with positive sums (R returns NaN here)");
    }
  }
  for (Eigen::Index j = 0; j < cols; ++j) {
    if (!(col_sums(j) > 0.0)) {
      ThrowBadValue("chi-squared table column " + std::to_string(j), "a sum of 0",
                    "rows and columns with positive sums (R returns NaN here)");
    }
  }
  Eigen::MatrixXd expected(rows, cols);
  for (Eigen::Index i = 0; i < rows; ++i) {
    for (Eigen::Index j = 0; j < cols; ++j) expected(i, j) = row_sums(i) * col_sums(j) / r.total;
  }
  // R: YATES = min(0.5, abs(x - E)) over the whole 2x2 table, subtracted from every |x - E|.
  double yates = 0.0;
  if (correct && rows == 2 && cols == 2) {
    yates = 0.5;
    for (Eigen::Index i = 0; i < 2; ++i) {
      for (Eigen::Index j = 0; j < 2; ++j) {
        yates = std::min(yates, std::abs(table(i, j) - expected(i, j)));
      }
    }
  }
  r.yates = yates > 0.0;
  r.method = r.yates ? "Pearson's Chi-squared test with Yates' continuity correction"
                     : "Pearson's Chi-squared test";
  double uncorrected = 0.0;
  for (Eigen::Index i = 0; i < rows; ++i) {
    for (Eigen::Index j = 0; j < cols; ++j) {
      const double e = expected(i, j);
      const double d = table(i, j) - e;
      const double corrected = std::abs(d) - yates;
      r.statistic += corrected * corrected / e;
      uncorrected += d * d / e;
      r.expected.push_back(e);
      r.residuals.push_back(d / std::sqrt(e));
      // R's V = c r (n - r) (n - c) / n^3 for row sum r and column sum c.
      const double v = col_sums(j) * row_sums(i) * (r.total - row_sums(i)) *
                       (r.total - col_sums(j)) / (r.total * r.total * r.total);
      r.standardized_residuals.push_back(d / std::sqrt(v));
      r.approximation_warning = r.approximation_warning || e < 5.0;
    }
  }
  r.df = static_cast<double>((rows - 1) * (cols - 1));
  r.p_value = UpperTail(r.statistic, r.df);
  r.effect_size_name = "cramers_v";
  r.effect_size =
      std::sqrt(uncorrected / (r.total * static_cast<double>(std::min(rows, cols) - 1)));
  return r;
}

}  // namespace mmh::stats
