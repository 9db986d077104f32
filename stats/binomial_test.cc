#include "stats/binomial_test.h"

#include <algorithm>
#include <boost/math/distributions/binomial.hpp>
#include <boost/math/special_functions/beta.hpp>
#include <cmath>

#include "core/error.h"
#include "core/options.h"

namespace mmh::stats {
namespace {

namespace bm = boost::math;

// P(X <= k) for X ~ Binomial(n, p); 0 for k < 0, 1 for k >= n (R's pbinom).
double LowerTail(const bm::binomial_distribution<double>& dist, std::int64_t k, std::int64_t n) {
  if (k < 0) return 0.0;
  if (k >= n) return 1.0;
  return bm::cdf(dist, static_cast<double>(k));
}

// P(X > k) (R's pbinom(k, n, p, lower.tail = FALSE)).
double UpperTail(const bm::binomial_distribution<double>& dist, std::int64_t k, std::int64_t n) {
  if (k < 0) return 1.0;
  if (k >= n) return 0.0;
  return bm::cdf(bm::complement(dist, static_cast<double>(k)));
}

}  // namespace

void BinomialTestOptions::Validate(const std::string& prefix) const {
  RequireProbability(p, prefix + ".p");
  RequireConfidenceLevel(conf_level, prefix + ".conf_level");
}

nlohmann::json BinomialTestResult::ToJson() const {
  return {{"test", "exact binomial test"},
          {"successes", successes},
          {"trials", trials},
          {"estimate", estimate},
          {"p_value", p_value},
          {"conf_int", conf_int.ToJson()},
          {"cohens_h", cohens_h},
          {"null_p", options.p},
          {"alternative", EnumName(options.alternative)}};
}

BinomialTestResult BinomialTest(std::int64_t successes, std::int64_t trials,
                                const BinomialTestOptions& options) {
  options.Validate("binomial test options");
  if (trials < 1) {
    ThrowBadValue("binomial test trials", std::to_string(trials), "at least 1 trial");
  }
  if (successes < 0 || successes > trials) {
    ThrowBadValue("binomial test successes", std::to_string(successes),
                  "an integer in [0, " + std::to_string(trials) + "]");
  }
  const std::int64_t x = successes;
  const std::int64_t n = trials;
  const double p = options.p;
  BinomialTestResult r;
  r.options = options;
  r.successes = x;
  r.trials = n;
  r.estimate = static_cast<double>(x) / static_cast<double>(n);
  r.cohens_h = 2.0 * std::asin(std::sqrt(r.estimate)) - 2.0 * std::asin(std::sqrt(p));

  const bm::binomial_distribution<double> dist(static_cast<double>(n), p);
  switch (options.alternative) {
    case Alternative::kLess:
      r.p_value = LowerTail(dist, x, n);
      break;
    case Alternative::kGreater:
      r.p_value = UpperTail(dist, x - 1, n);
      break;
    case Alternative::kTwoSided: {
      if (p == 0.0) {
        r.p_value = x == 0 ? 1.0 : 0.0;
      } else if (p == 1.0) {
        r.p_value = x == n ? 1.0 : 0.0;
      } else {
        // R's rule: outcomes on the other side of the mean n p that are at most (1 + 1e-7) times
        // as likely as the observed one count as "at least as extreme".
        const double relative_error = 1.0 + 1e-7;
        const double d = bm::pdf(dist, static_cast<double>(x));
        const double m = static_cast<double>(n) * p;
        if (static_cast<double>(x) == m) {
          r.p_value = 1.0;
        } else if (static_cast<double>(x) < m) {
          std::int64_t y = 0;
          for (auto i = static_cast<std::int64_t>(std::ceil(m)); i <= n; ++i) {
            if (bm::pdf(dist, static_cast<double>(i)) <= d * relative_error) ++y;
          }
          r.p_value = LowerTail(dist, x, n) + UpperTail(dist, n - y, n);
        } else {
          std::int64_t y = 0;
          const auto top = static_cast<std::int64_t>(std::floor(m));
          for (std::int64_t i = 0; i <= top; ++i) {
            if (bm::pdf(dist, static_cast<double>(i)) <= d * relative_error) ++y;
          }
          r.p_value = LowerTail(dist, y - 1, n) + UpperTail(dist, x - 1, n);
        }
        r.p_value = std::min(1.0, r.p_value);
      }
      break;
    }
  }

  // Clopper-Pearson ends: beta quantiles (R's qbeta), 0 and 1 at the edges.
  const auto lower_end = [&](double alpha) {
    return x == 0 ? 0.0
                  : bm::ibeta_inv(static_cast<double>(x), static_cast<double>(n - x + 1), alpha);
  };
  const auto upper_end = [&](double alpha) {
    return x == n
               ? 1.0
               : bm::ibeta_inv(static_cast<double>(x + 1), static_cast<double>(n - x), 1.0 - alpha);
  };
  const double level = options.conf_level;
  switch (options.alternative) {
    case Alternative::kLess:
      r.conf_int = {0.0, upper_end(1.0 - level), level};
      break;
    case Alternative::kGreater:
      r.conf_int = {lower_end(1.0 - level), 1.0, level};
      break;
    case Alternative::kTwoSided: {
      const double alpha = (1.0 - level) / 2.0;
      r.conf_int = {lower_end(alpha), upper_end(alpha), level};
      break;
    }
  }
  return r;
}

}  // namespace mmh::stats
