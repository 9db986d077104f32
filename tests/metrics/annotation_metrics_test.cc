#include "metrics/annotation_metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/error.h"
#include "tests/test_util.h"

namespace mmh::metrics {
namespace {

std::vector<double> Wave(int n, int shift = 0) {
  std::vector<double> v(n);
  for (int i = 0; i < n; ++i)
    v[i] = 4.0 * std::sin(0.05 * (i - shift)) + std::sin(0.31 * (i - shift));
  return v;
}

TEST(AnnotationMetricsTest, BiasRmseAndLag) {
  const std::vector<double> truth = Wave(400);
  std::vector<double> biased = truth;
  for (double& v : biased) v += 0.5;
  const AnnotationErrors e = CompareAnnotations(truth, biased);
  EXPECT_NEAR(e.rmse, 0.5, 1e-12);
  EXPECT_NEAR(e.bias, 0.5, 1e-12);
  EXPECT_NEAR(e.mean_absolute, 0.5, 1e-12);
  EXPECT_NEAR(e.lag_frames, 0.0, 1e-9);
  // A reader three frames late.
  const AnnotationErrors late = CompareAnnotations(truth, Wave(400, 3));
  EXPECT_NEAR(late.lag_frames, 3.0, 0.05);
}

TEST(AnnotationMetricsTest, ClippingShares) {
  std::vector<double> truth = Wave(100), read = Wave(100);
  truth[0] = truth[1] = 5.0;
  read[2] = -5.0;
  const AnnotationErrors e = CompareAnnotations(truth, read);
  EXPECT_DOUBLE_EQ(e.truth_clipped_share, 0.02);
  EXPECT_DOUBLE_EQ(e.read_clipped_share, 0.01);
}

TEST(AnnotationMetricsTest, MismatchedLengthsAreNamed) {
  EXPECT_NE(test_util::ErrorOf([] { CompareAnnotations(Wave(50), Wave(49)); }).find("49 values"),
            std::string::npos);
}

}  // namespace
}  // namespace mmh::metrics
