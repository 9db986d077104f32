// Friedman rank-sum test for an unreplicated complete block design, as R's friedman.test(y) with
// y a #blocks by #groups matrix: values are ranked within each block (average ranks for ties) and
// the statistic carries R's tie correction,
//   X = 12 sum_j (R_j - n (k + 1) / 2)^2 / (n k (k + 1) - sum_ties (t^3 - t) / (k - 1)),
// chi-squared with k - 1 degrees of freedom (Hollander & Wolfe 1973, p. 139). Effect size:
// Kendall's W = X / (n (k - 1)).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <vector>

namespace mmh::stats {

struct FriedmanResult {
  std::size_t blocks = 0;  // n (R: rows of y), e.g. animators
  std::size_t groups = 0;  // k (R: columns of y), e.g. the ranked animations
  double statistic = 0.0;  // Friedman chi-squared, tie-corrected
  double df = 0.0;         // k - 1
  double p_value = 0.0;    // upper tail of chi-squared(df)
  // sum over blocks of (t^3 - t) over the tie groups within each block (0 without ties).
  double tie_sum = 0.0;
  std::vector<double> rank_sums;   // per group (column)
  std::vector<double> mean_ranks;  // per group: rank_sums / n
  double kendalls_w = 0.0;         // statistic / (n (k - 1)), in [0, 1]

  nlohmann::json ToJson() const;
};

// `y`: #blocks by #groups. Throws InputError for non-finite values, fewer than 1 block or 2
// groups, or when every block is all ties (R returns NaN there: the statistic is 0 / 0).
FriedmanResult FriedmanTest(const Eigen::MatrixXd& y);

}  // namespace mmh::stats
