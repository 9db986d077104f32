#include "core/cross_correlation.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/error.h"

namespace mmh {

double CrossCorrelationLag(std::span<const double> reference, std::span<const double> delayed,
                           int max_lag) {
  const int n = static_cast<int>(std::min(reference.size(), delayed.size()));
  if (max_lag < 0 || n <= max_lag + 2) {
    ThrowBadValue("cross-correlation", std::to_string(n) + " samples",
                  "more than max_lag + 2 = " + std::to_string(max_lag + 2));
  }
  // Pearson correlation of reference[t] with delayed[t + lag] over the common range.
  std::vector<double> correlation(max_lag + 1);
  for (int lag = 0; lag <= max_lag; ++lag) {
    const int m = n - lag;
    double sa = 0, sb = 0;
    for (int t = 0; t < m; ++t) sa += reference[t], sb += delayed[t + lag];
    const double ma = sa / m, mb = sb / m;
    double ab = 0, aa = 0, bb = 0;
    for (int t = 0; t < m; ++t) {
      const double a = reference[t] - ma, b = delayed[t + lag] - mb;
      ab += a * b, aa += a * a, bb += b * b;
    }
    correlation[lag] = aa > 0 && bb > 0 ? ab / std::sqrt(aa * bb) : 0.0;
  }
  const int best = static_cast<int>(std::max_element(correlation.begin(), correlation.end()) -
                                    correlation.begin());
  if (best == 0 || best == max_lag) return best;
  // Parabola through the peak and its neighbours.
  const double c0 = correlation[best - 1], c1 = correlation[best], c2 = correlation[best + 1];
  const double denominator = c0 - 2 * c1 + c2;
  return denominator < 0 ? best + 0.5 * (c0 - c2) / denominator : best;
}

}  // namespace mmh
