// Exact binomial test, as R's binom.test(x, n, p, alternative, conf.level): one-sided tails, and
// R's two-sided rule (the probability of every outcome no more likely than the observed one, with
// a relative tolerance of 1e-7 on "no more likely"), Clopper-Pearson confidence interval.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "stats/htest.h"

namespace mmh::stats {

struct BinomialTestOptions {
  // Probability of success under the null hypothesis (R's p), in [0, 1].
  double p = 0.5;
  // Alternative hypothesis (R's alternative).
  Alternative alternative = Alternative::kTwoSided;
  // Coverage of the Clopper-Pearson interval (R's conf.level).
  double conf_level = 0.95;

  template <class V>
  void VisitFields(V& v) {
    v("p", p);
    v("alternative", alternative);
    v("conf_level", conf_level);
  }
  void Validate(const std::string& prefix) const;
};

struct BinomialTestResult {
  std::int64_t successes = 0;  // x (R's statistic)
  std::int64_t trials = 0;     // n (R's parameter)
  double estimate = 0.0;       // x / n
  double p_value = 0.0;
  ConfidenceInterval conf_int;  // Clopper-Pearson, for the probability of success
  // Cohen's h = 2 asin(sqrt(x / n)) - 2 asin(sqrt(p)).
  double cohens_h = 0.0;
  BinomialTestOptions options;

  nlohmann::json ToJson() const;
};

// Throws InputError unless 0 <= successes <= trials and trials >= 1.
BinomialTestResult BinomialTest(std::int64_t successes, std::int64_t trials,
                                const BinomialTestOptions& options = {});

}  // namespace mmh::stats
