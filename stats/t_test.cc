#include "stats/t_test.h"

#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/options.h"
#include "stats/descriptive.h"

namespace mmh::stats {

void TTestOptions::Validate(const std::string& prefix) const {
  RequireFinite(mu, prefix + ".mu");
  RequireConfidenceLevel(conf_level, prefix + ".conf_level");
}

nlohmann::json TTestResult::ToJson() const {
  return {{"test", "one-sample t-test"},
          {"n", n},
          {"mean", mean},
          {"sd", sd},
          {"standard_error", standard_error},
          {"t", t},
          {"df", df},
          {"p_value", p_value},
          {"conf_int", conf_int.ToJson()},
          {"cohens_d", cohens_d},
          {"mu", options.mu},
          {"alternative", EnumName(options.alternative)}};
}

TTestResult OneSampleTTest(std::span<const double> x, const TTestOptions& options) {
  options.Validate("t-test options");
  RequireAllFinite(x, "t-test sample");
  if (x.size() < 2) {
    ThrowBadValue("t-test sample", std::to_string(x.size()) + " values",
                  "at least 2 values (R: not enough 'x' observations)");
  }
  TTestResult r;
  r.options = options;
  r.n = x.size();
  r.mean = Mean(x);
  r.sd = std::sqrt(Variance(x));
  r.df = static_cast<double>(r.n - 1);
  r.standard_error = std::sqrt(Variance(x) / static_cast<double>(r.n));
  // R's guard against a statistic that is only rounding noise.
  if (r.standard_error < 10.0 * std::numeric_limits<double>::epsilon() * std::abs(r.mean)) {
    ThrowBadValue("t-test sample",
                  "essentially constant data (mean " + FormatNumber(r.mean) + ", standard error " +
                      FormatNumber(r.standard_error) + ")",
                  "data that vary (R: data are essentially constant)");
  }
  r.t = (r.mean - options.mu) / r.standard_error;
  r.cohens_d = (r.mean - options.mu) / r.sd;

  const boost::math::students_t_distribution<double> dist(r.df);
  const double inf = std::numeric_limits<double>::infinity();
  double low = 0.0;
  double high = 0.0;
  switch (options.alternative) {
    case Alternative::kLess:
      r.p_value = boost::math::cdf(dist, r.t);
      low = -inf;
      high = r.t + boost::math::quantile(dist, options.conf_level);
      break;
    case Alternative::kGreater:
      r.p_value = boost::math::cdf(boost::math::complement(dist, r.t));
      low = r.t - boost::math::quantile(dist, options.conf_level);
      high = inf;
      break;
    case Alternative::kTwoSided: {
      r.p_value = 2.0 * boost::math::cdf(dist, -std::abs(r.t));
      const double q = boost::math::quantile(dist, 1.0 - (1.0 - options.conf_level) / 2.0);
      low = r.t - q;
      high = r.t + q;
      break;
    }
  }
  // The interval in the data's unit, formed as R forms it (mu + (t -+ q) se), so that an end near
  // zero rounds the same way.
  r.conf_int.lower = std::isfinite(low) ? options.mu + low * r.standard_error : -inf;
  r.conf_int.upper = std::isfinite(high) ? options.mu + high * r.standard_error : inf;
  r.conf_int.level = options.conf_level;
  return r;
}

}  // namespace mmh::stats
