#include "metrics/trajectory_error.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "tests/test_util.h"

namespace mmh::metrics {
namespace {

Rigid3 Pose(double yaw, double x, double y, double z) {
  return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())),
                Eigen::Vector3d(x, y, z));
}

// evo's statistics of {1, 2, 3, 4} by hand: numpy's mean, median, std (ddof 0), min, max, the
// root of the mean square and the sum of squares.
TEST(TrajectoryErrorTest, StatisticsAreEvos) {
  const std::vector<double> e = {3, 1, 4, 2};
  const ErrorStatistics s = Statistics(e);
  EXPECT_EQ(s.count, 4);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));
  EXPECT_DOUBLE_EQ(s.min, 1);
  EXPECT_DOUBLE_EQ(s.max, 4);
  EXPECT_DOUBLE_EQ(s.sse, 30);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));
  const nlohmann::json j = ToJson(s);
  for (const char* key : {"rmse", "mean", "median", "std", "min", "max", "sse"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(Statistics(std::vector<double>{}).count, 0);
}

TEST(TrajectoryErrorTest, AbsoluteErrorIsTheDistanceOfThePositions) {
  const std::vector<Rigid3> reference = {Pose(0, 0, 0, 0), Pose(1, 1, 0, 0)};
  const std::vector<Rigid3> estimate = {Pose(0.5, 0.003, 0.004, 0), Pose(1, 1, 0, 0.002)};
  const std::vector<double> e = AbsoluteTranslationErrors(estimate, reference);
  ASSERT_EQ(e.size(), 2u);
  EXPECT_NEAR(e[0], 0.005, 1e-15);
  EXPECT_NEAR(e[1], 0.002, 1e-15);
  EXPECT_NE(test_util::ErrorOf([&] {
              AbsoluteTranslationErrors(std::vector<Rigid3>(1), reference);
            }).find("1 estimated poses"),
            std::string::npos);
}

// RPE does not see a global transform of the estimate (APE does), and a one-frame jump shows
// in the two steps around it.
TEST(TrajectoryErrorTest, RelativeErrorIgnoresAGlobalTransformAndSeesAJump) {
  std::vector<Rigid3> reference, moved;
  const Rigid3 global = Pose(0.7, 0.2, -0.1, 0.05);
  for (int i = 0; i < 20; ++i) {
    reference.push_back(Pose(0.05 * i, 0.01 * i, 0.002 * i * i, 0));
    moved.push_back(global * reference.back());
  }
  const RelativeErrors still = RelativePoseErrors(moved, reference, 1);
  ASSERT_EQ(still.translation.size(), 19u);
  for (size_t i = 0; i < still.translation.size(); ++i) {
    EXPECT_NEAR(still.translation[i], 0.0, 1e-12);
    EXPECT_NEAR(still.rotation_deg[i], 0.0, 1e-5);
  }
  EXPECT_GT(Statistics(AbsoluteTranslationErrors(moved, reference)).min, 0.05);

  std::vector<Rigid3> flat(10), jumped(10);
  for (int i = 0; i < 10; ++i) flat[i] = jumped[i] = Pose(0, 0.01 * i, 0, 0);
  jumped[5].translation.z() += 0.004;
  const RelativeErrors r = RelativePoseErrors(jumped, flat, 1);
  for (int i = 0; i < 9; ++i) {
    EXPECT_NEAR(r.translation[i], i == 4 || i == 5 ? 0.004 : 0.0, 1e-12) << i;
  }
  EXPECT_EQ(RelativePoseErrors(jumped, flat, 3).translation.size(), 7u);
}

}  // namespace
}  // namespace mmh::metrics
