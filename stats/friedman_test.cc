#include "stats/friedman_test.h"

#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <map>

#include "core/error.h"
#include "stats/descriptive.h"
#include "stats/htest.h"

namespace mmh::stats {

nlohmann::json FriedmanResult::ToJson() const {
  return {{"test", "Friedman rank sum test"},
          {"blocks", blocks},
          {"groups", groups},
          {"statistic", statistic},
          {"df", df},
          {"p_value", p_value},
          {"tie_sum", tie_sum},
          {"rank_sums", rank_sums},
          {"mean_ranks", mean_ranks},
          {"kendalls_w", kendalls_w}};
}

FriedmanResult FriedmanTest(const Eigen::MatrixXd& y) {
  if (y.rows() < 1 || y.cols() < 2) {
    ThrowBadValue("Friedman test data",
                  std::to_string(y.rows()) + " blocks by " + std::to_string(y.cols()) + " groups",
                  "at least 1 block and 2 groups");
  }
  if (!y.allFinite()) {
    ThrowBadValue("Friedman test data", "a non-finite value", "finite values only");
  }
  FriedmanResult r;
  r.blocks = static_cast<std::size_t>(y.rows());
  r.groups = static_cast<std::size_t>(y.cols());
  const double n = static_cast<double>(r.blocks);
  const double k = static_cast<double>(r.groups);
  r.rank_sums.assign(r.groups, 0.0);
  std::vector<double> row(r.groups);
  for (Eigen::Index i = 0; i < y.rows(); ++i) {
    for (Eigen::Index j = 0; j < y.cols(); ++j) row[j] = y(i, j);
    const std::vector<double> ranks = AverageRanks(row);
    std::map<double, int> ties;  // rank -> size of its tie group
    for (std::size_t j = 0; j < r.groups; ++j) {
      r.rank_sums[j] += ranks[j];
      ++ties[ranks[j]];
    }
    for (const auto& [rank, count] : ties) {
      const double t = count;
      r.tie_sum += t * t * t - t;
    }
  }
  double sum_squares = 0.0;
  for (double rank_sum : r.rank_sums) {
    const double d = rank_sum - n * (k + 1.0) / 2.0;
    sum_squares += d * d;
  }
  const double denominator = n * k * (k + 1.0) - r.tie_sum / (k - 1.0);
  if (!(denominator > 0.0)) {
    ThrowBadValue("Friedman test data", "every block is all ties",
                  "at least one block with two different values (R returns NaN here)");
  }
  r.statistic = 12.0 * sum_squares / denominator;
  r.df = k - 1.0;
  r.p_value = boost::math::cdf(
      boost::math::complement(boost::math::chi_squared_distribution<double>(r.df), r.statistic));
  for (double rank_sum : r.rank_sums) r.mean_ranks.push_back(rank_sum / n);
  r.kendalls_w = r.statistic / (n * (k - 1.0));
  return r;
}

}  // namespace mmh::stats
