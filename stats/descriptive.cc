#include "stats/descriptive.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace mmh::stats {

double Mean(std::span<const double> x) {
  if (x.empty()) return std::numeric_limits<double>::quiet_NaN();
  const long double n = static_cast<long double>(x.size());
  long double sum = 0.0L;
  for (double v : x) sum += v;
  long double mean = sum / n;
  // Second pass: adds the mean of the residuals, which recovers the bits lost in the first sum.
  if (std::isfinite(static_cast<double>(mean))) {
    long double correction = 0.0L;
    for (double v : x) correction += static_cast<long double>(v) - mean;
    mean += correction / n;
  }
  return static_cast<double>(mean);
}

double Variance(std::span<const double> x) {
  if (x.size() < 2) return std::numeric_limits<double>::quiet_NaN();
  const long double mean = Mean(x);
  long double sum = 0.0L;
  for (double v : x) {
    const long double d = static_cast<long double>(v) - mean;
    sum += d * d;
  }
  return static_cast<double>(sum / static_cast<long double>(x.size() - 1));
}

std::vector<double> AverageRanks(std::span<const double> x) {
  std::vector<std::size_t> order(x.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return x[a] < x[b]; });
  std::vector<double> ranks(x.size());
  for (std::size_t begin = 0; begin < order.size();) {
    std::size_t end = begin + 1;
    while (end < order.size() && x[order[end]] == x[order[begin]]) ++end;
    // Positions begin..end-1 hold ranks begin+1..end; their average is (begin + 1 + end) / 2.
    const double rank = 0.5 * static_cast<double>(begin + 1 + end);
    for (std::size_t i = begin; i < end; ++i) ranks[order[i]] = rank;
    begin = end;
  }
  return ranks;
}

}  // namespace mmh::stats
