// One-sample Student t-test, as R's t.test(x, mu = , alternative = , conf.level = ), with the
// standardised effect size (Cohen's d).
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <span>
#include <string>

#include "stats/htest.h"

namespace mmh::stats {

struct TTestOptions {
  // Mean under the null hypothesis (R's mu), in the unit of the data.
  double mu = 0.0;
  // Alternative hypothesis (R's alternative).
  Alternative alternative = Alternative::kTwoSided;
  // Coverage of the confidence interval for the mean (R's conf.level).
  double conf_level = 0.95;

  template <class V>
  void VisitFields(V& v) {
    v("mu", mu);
    v("alternative", alternative);
    v("conf_level", conf_level);
  }
  void Validate(const std::string& prefix) const;
};

struct TTestResult {
  std::size_t n = 0;
  double mean = 0.0;            // sample mean (R's estimate)
  double sd = 0.0;              // sample standard deviation (denominator n - 1)
  double standard_error = 0.0;  // sd / sqrt(n)
  double t = 0.0;               // (mean - mu) / standard_error (R's statistic)
  double df = 0.0;              // n - 1 (R's parameter)
  double p_value = 0.0;
  ConfidenceInterval conf_int;  // for the mean; one-sided for "less" and "greater"
  double cohens_d = 0.0;        // (mean - mu) / sd
  TTestOptions options;

  nlohmann::json ToJson() const;
};

// Throws InputError for a non-finite value, fewer than two values ("not enough 'x'
// observations" in R) or essentially constant data (standard error < 10 eps |mean|, R's "data are
// essentially constant"): the statistic is undefined there.
TTestResult OneSampleTTest(std::span<const double> x, const TTestOptions& options = {});

}  // namespace mmh::stats
