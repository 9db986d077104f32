#include "metrics/motion_metrics.h"

#include <gtest/gtest.h>

#include <vector>

namespace mmh::metrics {
namespace {

// Uniform motion changes nothing from frame to frame; a 5 mm step shows as a jump in position at
// the step and in velocity on both sides of it.
TEST(MotionMetricsTest, UniformMotionIsSmoothAndAStepIsAJump) {
  const double fps = 30.0;
  std::vector<Rigid3> poses;
  for (int i = 0; i < 30; ++i) {
    poses.emplace_back(Eigen::Quaterniond(Eigen::AngleAxisd(0.02 * i, Eigen::Vector3d::UnitZ())),
                       Eigen::Vector3d(0.001 * i, 0, 0));
  }
  MotionChanges c = ComputeMotionChanges(poses, fps);
  for (int t = 1; t + 1 < 30; ++t) {
    EXPECT_NEAR(c.position[t], 0.001, 1e-12);
    EXPECT_NEAR(c.velocity[t], 0.0, 1e-12);
    EXPECT_NEAR(c.angular_velocity[t], 0.0, 1e-9);
  }
  for (int i = 15; i < 30; ++i) poses[i].translation.y() += 0.005;
  c = ComputeMotionChanges(poses, fps);
  EXPECT_NEAR(c.position[15], std::hypot(0.001, 0.005), 1e-12);
  EXPECT_NEAR(c.velocity[15], 0.005 * fps, 1e-9);  // v(15) − v(14) = −(p15 − p14)'s y part
  EXPECT_NEAR(c.velocity[14], 0.005 * fps, 1e-9);
  EXPECT_NEAR(c.velocity[16], 0.0, 1e-9);
  EXPECT_NEAR(WindowMax(c.position, 13, 2), c.position[15], 0);
  EXPECT_NEAR(WindowMax(c.position, 10, 2), 0.001, 1e-12);
}

}  // namespace
}  // namespace mmh::metrics
