// The summary statistics against R and brute force; Slurm's --array ranges.
#include "sweep/aggregate.h"

#include <gtest/gtest.h>

#include <cmath>

#include "sweep/slurm_backend.h"

namespace mmh::sweep {
namespace {

TEST(SweepAggregateTest, MeanSdAndCiMatchR) {
  // R: x <- c(2.1, 3.4, 1.9, 5.0, 4.2); t.test(x)$conf.int; sd(x)
  //   mean 3.32, sd 1.333041635, CI [1.664810194, 4.975189806]
  const MeanCi d = Describe({2.1, 3.4, 1.9, 5.0, 4.2});
  EXPECT_EQ(d.n, 5);
  EXPECT_NEAR(d.mean, 3.32, 1e-12);
  EXPECT_NEAR(d.sd, 1.333041635, 1e-9);
  EXPECT_NEAR(d.ci_low, 1.664810194, 1e-9);
  EXPECT_NEAR(d.ci_high, 4.975189806, 1e-9);
  EXPECT_DOUBLE_EQ(d.median, 3.4);
  EXPECT_TRUE(std::isnan(Describe({1.0}).sd));
  EXPECT_EQ(CsvNumber(Describe({1.0}).ci_low), "");
}

TEST(SweepAggregateTest, VarianceShareIsTheBetweenGroupSumOfSquaresShare) {
  const std::vector<double> v = {1, 2, 3, 7, 8, 9};
  // Brute force: grand mean 5, total SS = 16+9+4+4+9+16 = 58; group means 2 and 8, between SS
  // = 3*9 + 3*9 = 54.
  EXPECT_NEAR(VarianceShare(v, {0, 0, 0, 1, 1, 1}), 54.0 / 58.0, 1e-15);
  // Groups {1, 7}, {2, 8}, {3, 9}: means 4, 5, 6, between SS = 2 * (1 + 0 + 1) = 4.
  EXPECT_NEAR(VarianceShare(v, {0, 1, 2, 0, 1, 2}), 4.0 / 58.0, 1e-15);
  EXPECT_NEAR(VarianceShare(v, {0, 1, 2, 3, 4, 5}), 1.0, 1e-15);
  EXPECT_NEAR(VarianceShare(v, {0, 0, 0, 0, 0, 0}), 0.0, 1e-15);
}

TEST(SweepAggregateTest, ArrayRangesCompress) {
  EXPECT_EQ(ArrayRanges({7, 0, 1, 2, 3, 9, 10}), "0-3,7,9-10");
  EXPECT_EQ(ArrayRanges({4}), "4");
  EXPECT_EQ(ArrayRanges({}), "");
}

}  // namespace
}  // namespace mmh::sweep
