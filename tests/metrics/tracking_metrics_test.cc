// Tracking metrics against analytic values: known rotations and offsets, ADD of a pure translation,
// ADD-S of a symmetric object's turn, quantiles as R's quantile(type = 7), failure runs.
#include "metrics/tracking_metrics.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <numbers>
#include <random>

#include "core/error.h"
#include "tests/test_util.h"

namespace mmh::metrics {
namespace {

using ::testing::HasSubstr;

Eigen::Matrix<double, Eigen::Dynamic, 3> Square() {
  // Four points of a 2 m square around the origin in the xy plane: diameter 2 sqrt 2.
  Eigen::Matrix<double, Eigen::Dynamic, 3> points(4, 3);
  points << 1, 1, 0, -1, 1, 0, -1, -1, 0, 1, -1, 0;
  return points;
}

TEST(TrackingMetricsTest, ErrorsOfKnownPoses) {
  const auto points = Square();
  EXPECT_NEAR(Diameter(points), 2 * std::sqrt(2.0), 1e-12);
  const Rigid3 truth(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX())),
                     Eigen::Vector3d(0.1, 0.2, 1.0));
  // Shifted by 3 mm along x: ADD = ADD-S = 3 mm (ADD-S: each point's nearest is its own image).
  Rigid3 shifted = truth;
  shifted.translation.x() += 0.003;
  // Turned by 90 deg about z (in the object's frame): the square maps onto itself, so ADD-S = 0
  // while ADD = the distance of each corner to its neighbour, 2 m.
  const Rigid3 turned =
      truth *
      Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ())),
             Eigen::Vector3d::Zero());
  const std::vector<std::optional<Rigid3>> estimates = {shifted, turned, std::nullopt};
  const std::vector<Rigid3> truths = {truth, truth, truth};
  const auto errors = ComputePoseErrors(estimates, truths, points, PoseErrorOptions());
  ASSERT_EQ(errors.size(), 3u);
  EXPECT_NEAR(errors[0].rotation_deg, 0.0, 1e-6);
  EXPECT_NEAR(errors[0].translation, 0.003, 1e-12);
  EXPECT_NEAR(errors[0].add, 0.003, 1e-12);
  EXPECT_NEAR(errors[0].adds, 0.003, 1e-12);
  EXPECT_TRUE(errors[0].success);
  EXPECT_NEAR(errors[1].rotation_deg, 90.0, 1e-9);
  EXPECT_NEAR(errors[1].translation, 0.0, 1e-12);
  EXPECT_NEAR(errors[1].add, 2.0, 1e-12);
  EXPECT_NEAR(errors[1].adds, 0.0, 1e-12);
  EXPECT_FALSE(errors[1].success);
  EXPECT_FALSE(errors[2].has_estimate);
  EXPECT_FALSE(errors[2].success);

  const auto summary = SummarizeTracking(errors, Diameter(points), PoseErrorOptions());
  EXPECT_EQ(summary.frames, 3);
  EXPECT_EQ(summary.frames_with_estimate, 2);
  EXPECT_NEAR(summary.median_rotation_deg, 45.0, 1e-9);  // of 0 and 90
  EXPECT_NEAR(summary.success_rate, 1.0 / 3, 1e-12);
  EXPECT_NEAR(summary.adds_success_rate, 2.0 / 3, 1e-12);  // 0.003 and 0 < 0.28
  EXPECT_NEAR(summary.add_success_rate, 1.0 / 3, 1e-12);
  ASSERT_EQ(summary.failures.size(), 1u);
  EXPECT_EQ(summary.failures[0].first, 1);
  EXPECT_EQ(summary.failures[0].length, 2);
  EXPECT_FALSE(summary.failures[0].recovered);
  EXPECT_FALSE(summary.all_recovered);
  EXPECT_EQ(ToJson(summary)["longest_failure_frames"], 2);
}

TEST(TrackingMetricsTest, FailureRunsAndRecovery) {
  std::vector<FramePoseError> errors(10);
  for (auto& e : errors) e.success = e.has_estimate = true;
  errors[2].success = errors[3].success = false;  // a loss of 2 frames, recovered
  errors[6].success = errors[7].success = errors[8].success = false;  // 3 frames, recovered at 9
  const auto summary = SummarizeTracking(errors, 1.0, PoseErrorOptions());
  ASSERT_EQ(summary.failures.size(), 2u);
  EXPECT_EQ(summary.failures[1].first, 6);
  EXPECT_EQ(summary.failures[1].length, 3);
  EXPECT_TRUE(summary.failures[1].recovered);
  EXPECT_EQ(summary.longest_failure, 3);
  EXPECT_TRUE(summary.all_recovered);
  EXPECT_NEAR(summary.success_rate, 0.5, 1e-12);
}

TEST(TrackingMetricsTest, QuantileIsRsType7) {
  // R: quantile(c(3, 1, 4, 1, 5), c(0, 0.25, 0.5, 0.9, 1)) = 1 1 3 4.6 5
  const std::vector<double> values = {3, 1, 4, 1, 5};
  EXPECT_DOUBLE_EQ(Quantile(values, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(Quantile(values, 0.25), 1.0);
  EXPECT_DOUBLE_EQ(Quantile(values, 0.5), 3.0);
  EXPECT_NEAR(Quantile(values, 0.9), 4.6, 1e-12);
  EXPECT_DOUBLE_EQ(Quantile(values, 1.0), 5.0);
  EXPECT_DOUBLE_EQ(Quantile({}, 0.5), 0.0);
}

TEST(TrackingMetricsTest, BadInput) {
  const auto points = Square();
  EXPECT_THAT(test_util::ErrorOf([&] {
                ComputePoseErrors({std::nullopt}, {Rigid3(), Rigid3()}, points, PoseErrorOptions());
              }),
              HasSubstr("1 estimates"));
  PoseErrorOptions bad;
  bad.success_translation = -1;
  EXPECT_THAT(test_util::ErrorOf([&] { bad.Validate("metrics"); }),
              HasSubstr("metrics.success_translation"));
}

TEST(TrackingMetricsTest, MetricPointsAreDistinctVertices) {
  TriangleMesh mesh;
  mesh.vertices.resize(6, 3);
  mesh.vertices << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1;  // duplicated per face
  mesh.faces.resize(2, 3);
  mesh.faces << 0, 1, 2, 3, 4, 5;
  mesh.face_colors.setConstant(2, 3, 100);
  EXPECT_EQ(MetricPoints(mesh).rows(), 4);
  EXPECT_EQ(MetricPoints(mesh, 2).rows(), 2);
}

}  // namespace
}  // namespace mmh::metrics

namespace mmh::metrics {
namespace {

// ADD-S's nearest-neighbour search against brute force, on random points and poses.
TEST(TrackingMetricsTest, AddSMatchesBruteForce) {
  std::mt19937 rng(5);
  std::normal_distribution<double> normal(0.0, 0.02);
  Eigen::Matrix<double, Eigen::Dynamic, 3> points(300, 3);
  for (int i = 0; i < 300; ++i) points.row(i) << normal(rng), normal(rng), 2 * normal(rng);
  std::vector<std::optional<Rigid3>> estimates;
  std::vector<Rigid3> truth;
  for (int f = 0; f < 20; ++f) {
    const Eigen::Quaterniond q(Eigen::AngleAxisd(0.3 * f, Eigen::Vector3d(1, f, 2).normalized()));
    truth.emplace_back(q, Eigen::Vector3d(normal(rng), normal(rng), 0.6));
    const Eigen::Quaterniond e =
        q * Eigen::Quaterniond(Eigen::AngleAxisd(0.05 * f, Eigen::Vector3d::UnitY()));
    estimates.emplace_back(Rigid3(e, truth.back().translation + Eigen::Vector3d(0.001 * f, 0, 0)));
  }
  const auto errors = ComputePoseErrors(estimates, truth, points, PoseErrorOptions{});
  for (int f = 0; f < 20; ++f) {
    double adds = 0.0;
    for (int i = 0; i < 300; ++i) {
      const Eigen::Vector3d b = truth[f] * Eigen::Vector3d(points.row(i).transpose());
      double nearest = 1e300;
      for (int j = 0; j < 300; ++j) {
        const Eigen::Vector3d a = *estimates[f] * Eigen::Vector3d(points.row(j).transpose());
        nearest = std::min(nearest, (b - a).norm());
      }
      adds += nearest;
    }
    EXPECT_NEAR(errors[f].adds, adds / 300, 1e-12) << f;
  }
}

}  // namespace
}  // namespace mmh::metrics
