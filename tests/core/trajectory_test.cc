// Tests of core/trajectory.h: MedianFramePeriod and ValidateTrajectory.
#include "core/trajectory.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "core/error.h"

namespace mmh {
namespace {

using ::testing::HasSubstr;

Trajectory Uniform(std::size_t n, double period = 1.0 / 30.0) {
  Trajectory trajectory;
  for (std::size_t i = 0; i < n; ++i) {
    trajectory.timestamps.push_back(static_cast<double>(i) * period);
    trajectory.poses.emplace_back(Eigen::Quaterniond(Eigen::AngleAxisd(
                                      0.01 * static_cast<double>(i), Eigen::Vector3d::UnitY())),
                                  Eigen::Vector3d(0.001 * static_cast<double>(i), 0, 1));
  }
  return trajectory;
}

std::string ValidateError(const Trajectory& trajectory, const std::string& name) {
  try {
    ValidateTrajectory(trajectory, name);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "ValidateTrajectory accepted the trajectory";
  return "";
}

TEST(Trajectory, SizeAndEmpty) {
  Trajectory trajectory;
  EXPECT_TRUE(trajectory.empty());
  EXPECT_EQ(trajectory.size(), 0u);
  trajectory = Uniform(4);
  EXPECT_FALSE(trajectory.empty());
  EXPECT_EQ(trajectory.size(), 4u);
}

TEST(Trajectory, MedianFramePeriodOfFewFramesIsZero) {
  EXPECT_EQ(MedianFramePeriod({}), 0.0);
  EXPECT_EQ(MedianFramePeriod({1.0}), 0.0);
}

TEST(Trajectory, MedianFramePeriodOfTwoFrames) {
  EXPECT_DOUBLE_EQ(MedianFramePeriod({1.0, 1.25}), 0.25);
}

TEST(Trajectory, MedianFramePeriodOfUniformSequence) {
  const Trajectory trajectory = Uniform(100);
  EXPECT_NEAR(MedianFramePeriod(trajectory.timestamps), 1.0 / 30.0, 1e-12);
}

TEST(Trajectory, MedianFramePeriodIsRobustToDroppedFrames) {
  // 30 Hz with two dropped frames (gaps of 2 and 3 periods) and one early frame.
  std::vector<double> t;
  for (int i = 0; i < 20; ++i) {
    if (i == 5 || i == 11 || i == 12) continue;
    t.push_back(i / 30.0);
  }
  EXPECT_NEAR(MedianFramePeriod(t), 1.0 / 30.0, 1e-12);
}

TEST(Trajectory, MedianFramePeriodOddNumberOfPeriods) {
  // Periods 0.1, 0.5, 0.2 -> median 0.2, whatever the order.
  EXPECT_NEAR(MedianFramePeriod({0.0, 0.1, 0.6, 0.8}), 0.2, 1e-12);
  EXPECT_NEAR(MedianFramePeriod({0.0, 0.5, 0.6, 0.8}), 0.2, 1e-12);
}

TEST(Trajectory, MedianFramePeriodEvenNumberOfPeriodsIsBetweenTheMiddleTwo) {
  // Periods 1, 2, 10, 20: any value in [2, 10] is a median (the mean of the middle two is 6).
  const double median = MedianFramePeriod({0.0, 1.0, 3.0, 13.0, 33.0});
  EXPECT_GE(median, 2.0);
  EXPECT_LE(median, 10.0);
}

TEST(Trajectory, MedianFramePeriodDoesNotNeedSortedInput) {
  // The argument is const: the caller's vector is unchanged.
  const std::vector<double> t = {0.0, 0.1, 0.3, 0.4};
  const std::vector<double> copy = t;
  (void)MedianFramePeriod(t);
  EXPECT_EQ(t, copy);
}

TEST(Trajectory, ValidTrajectoriesPass) {
  EXPECT_NO_THROW(ValidateTrajectory(Trajectory{}, "empty"));
  EXPECT_NO_THROW(ValidateTrajectory(Uniform(1), "one"));
  EXPECT_NO_THROW(ValidateTrajectory(Uniform(50), "fifty"));
  // Negative timestamps are fine as long as they increase.
  Trajectory negative = Uniform(3);
  negative.timestamps = {-2.0, -1.0, 0.0};
  EXPECT_NO_THROW(ValidateTrajectory(negative, "negative"));
  // A quaternion with norm within 1e-6 of 1 is accepted.
  Trajectory almost = Uniform(2);
  almost.poses[1].rotation.coeffs() *= (1.0 + 5e-7);
  EXPECT_NO_THROW(ValidateTrajectory(almost, "almost"));
}

TEST(Trajectory, SizeMismatchIsRejected) {
  Trajectory trajectory = Uniform(5);
  trajectory.timestamps.pop_back();
  const std::string message = ValidateError(trajectory, "take 3");
  EXPECT_THAT(message, HasSubstr("take 3"));
  EXPECT_THAT(message, HasSubstr("4 timestamps for 5 poses"));
}

TEST(Trajectory, NonIncreasingTimestampsAreRejected) {
  Trajectory equal = Uniform(5);
  equal.timestamps[3] = equal.timestamps[2];
  const std::string message = ValidateError(equal, "a.tum");
  EXPECT_THAT(message, HasSubstr("a.tum, frame 3"));
  EXPECT_THAT(message, HasSubstr("timestamp"));
  EXPECT_THAT(message, HasSubstr(FormatNumber(equal.timestamps[2])));

  Trajectory decreasing = Uniform(5);
  decreasing.timestamps[1] = -1.0;
  const std::string message2 = ValidateError(decreasing, "take 1");
  EXPECT_THAT(message2, HasSubstr("take 1, frame 1"));
  EXPECT_THAT(message2, HasSubstr("-1"));
}

TEST(Trajectory, NonFiniteValuesAreRejected) {
  Trajectory nan_time = Uniform(3);
  nan_time.timestamps[0] = std::nan("");
  EXPECT_THAT(ValidateError(nan_time, "t"), HasSubstr("t, frame 0"));
  EXPECT_THAT(ValidateError(nan_time, "t"), HasSubstr("nan"));

  Trajectory inf_time = Uniform(3);
  inf_time.timestamps[2] = std::numeric_limits<double>::infinity();
  EXPECT_THAT(ValidateError(inf_time, "t"), HasSubstr("frame 2"));

  Trajectory nan_translation = Uniform(3);
  nan_translation.poses[1].translation.y() = std::nan("");
  EXPECT_THAT(ValidateError(nan_translation, "t"), HasSubstr("t, frame 1"));

  Trajectory nan_rotation = Uniform(3);
  nan_rotation.poses[2].rotation.x() = std::nan("");
  EXPECT_THAT(ValidateError(nan_rotation, "t"), HasSubstr("t, frame 2"));
}

TEST(Trajectory, NonUnitQuaternionIsRejected) {
  Trajectory trajectory = Uniform(4);
  trajectory.poses[2].rotation = Eigen::Quaterniond(2, 0, 0, 0);
  const std::string message = ValidateError(trajectory, "take 2");
  EXPECT_THAT(message, HasSubstr("take 2, frame 2"));
  EXPECT_THAT(message, HasSubstr("norm"));
  EXPECT_THAT(message, HasSubstr("got 2"));

  Trajectory slightly = Uniform(2);
  slightly.poses[0].rotation.coeffs() *= (1.0 + 1e-5);
  EXPECT_THAT(ValidateError(slightly, "s"), HasSubstr("s, frame 0"));

  Trajectory zero = Uniform(2);
  zero.poses[1].rotation = Eigen::Quaterniond(0, 0, 0, 0);
  EXPECT_THAT(ValidateError(zero, "z"), HasSubstr("z, frame 1"));
}

}  // namespace
}  // namespace mmh
