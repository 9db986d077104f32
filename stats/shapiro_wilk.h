// Shapiro-Wilk test of normality by Royston's algorithm AS R94 (Royston 1995, Appl. Statist.
// 44(4), 547-551; the approximation of Royston 1992, Statistics and Computing 2, 117-119), as R's
// shapiro.test: 3 <= n <= 5000, the exact p-value for n = 3, a log-normal approximation of 1 - W
// for 4 <= n <= 11 and a normal one of log(1 - W) for n >= 12.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <span>

namespace mmh::stats {

struct ShapiroWilkResult {
  std::size_t n = 0;
  double w = 0.0;        // W statistic, in (0, 1]
  double p_value = 0.0;  // probability of a W this small under normality

  nlohmann::json ToJson() const;
};

// Throws InputError for a non-finite value, n outside [3, 5000], or identical values (R: "all 'x'
// values are identical"; W is 0 / 0 there). Like R, data with a range below 1e-10 are rescaled by
// their range first.
ShapiroWilkResult ShapiroWilkTest(std::span<const double> x);

}  // namespace mmh::stats
