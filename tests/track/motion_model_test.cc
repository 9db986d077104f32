#include "track/motion_model.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <tuple>
#include <utility>

#include "core/error.h"

namespace mmh::track {
namespace {

const Eigen::Vector3d kCentroid(0.01, -0.02, 0.05);
constexpr double kRadius = 0.06;

Rigid3 Pose(double angle, const Eigen::Vector3d& axis, const Eigen::Vector3d& translation) {
  return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis.normalized())), translation);
}

// Rotation angle [rad] and translation [m] between two poses.
double AngleBetween(const Rigid3& a, const Rigid3& b) {
  return RotationAngle(a.rotation, b.rotation);
}
double DistanceBetween(const Rigid3& a, const Rigid3& b) {
  return (a.translation - b.translation).norm();
}

TEST(MotionModelTest, NothingToPredictBeforeTheFirstMeasurement) {
  MotionModel motion({}, kCentroid, kRadius);
  EXPECT_FALSE(motion.Predict());
  EXPECT_FALSE(motion.last());
}

TEST(MotionModelTest, WithoutAStepThePredictionIsTheLastPose) {
  MotionModel motion({}, kCentroid, kRadius);
  const Rigid3 pose = Pose(0.3, {1, 2, 3}, {0.1, -0.05, 1.2});
  motion.Measure(pose, true);  // the first pose: nothing to continue from
  ASSERT_TRUE(motion.Predict());
  EXPECT_EQ(AngleBetween(*motion.Predict(), pose), 0.0);
  EXPECT_EQ(DistanceBetween(*motion.Predict(), pose), 0.0);
  // A pose that does not continue the last one (a detection) makes no step either.
  const Rigid3 jumped = Pose(1.0, {0, 0, 1}, {0.2, 0.0, 1.1});
  motion.Measure(jumped, false);
  EXPECT_EQ(DistanceBetween(*motion.Predict(), jumped), 0.0);
}

// A constant step (each pose is the last one times the same motion, here a screw about a tilted
// axis with a drift): the persistence is 1 and the prediction is the next pose.
TEST(MotionModelTest, AConstantStepIsContinuedExactly) {
  MotionModel motion({}, kCentroid, kRadius);
  const Rigid3 step = Pose(0.05, {0.2, 1, 0.3}, {0.004, -0.002, 0.003});
  Rigid3 pose = Pose(0.4, {1, 0, 1}, {0.05, 0.1, 1.2});
  for (int k = 0; k < 20; ++k) {
    motion.Measure(pose, true);
    pose = pose * step;
    if (k < 2) continue;
    EXPECT_NEAR(motion.persistence(), 1.0, 1e-12);
    EXPECT_LT(AngleBetween(*motion.Predict(), pose), 1e-9) << k;
    EXPECT_LT(DistanceBetween(*motion.Predict(), pose), 1e-9) << k;
  }
}

// Steps that reverse every frame (a tremor at half the frame rate): the persistence falls to 0 and
// the prediction is the last pose; with adaptive off it continues the last step (constant
// velocity), twice as far from the truth's mean.
TEST(MotionModelTest, AReversingTremorIsNotContinued) {
  for (bool adaptive : {true, false}) {
    MotionOptions options;
    options.adaptive = adaptive;
    MotionModel motion(options, kCentroid, kRadius);
    const Rigid3 base = Pose(0.2, {0, 1, 0}, {0.0, 0.05, 1.1});
    const Rigid3 shake = Pose(0.02, {1, 0, 0}, {0.005, 0.0, -0.003});
    for (int k = 0; k < 12; ++k) motion.Measure(k % 2 ? base * shake : base, true);
    // Last measured: base (k = 11 is odd: base * shake). The true next pose is base.
    const Rigid3 last = *motion.last();
    const Rigid3 predicted = *motion.Predict();
    SCOPED_TRACE(adaptive ? "adaptive" : "constant velocity");
    if (adaptive) {
      EXPECT_NEAR(motion.factor(), -1.0, 1e-3);  // the back step is seen from the shaken frame
      EXPECT_EQ(motion.persistence(), 0.0);
      EXPECT_LT(DistanceBetween(predicted, last), 1e-12);
      EXPECT_LT(AngleBetween(predicted, last), 1e-12);
    } else {
      EXPECT_EQ(motion.persistence(), 1.0);
      // Continued past base * shake by another shake's worth, away from base.
      EXPECT_GT(DistanceBetween(predicted, base), 1.5 * DistanceBetween(last, base));
    }
  }
}

// Steps drawn independently (no persistence): the estimate lands near 0; steps made of a
// persistent drift plus independent noise give the least-squares AR(1) factor
// |drift|^2 / (|drift|^2 + E|noise|^2).
TEST(MotionModelTest, PersistenceIsTheLeastSquaresFactorBetweenSteps) {
  std::mt19937_64 random(7);
  std::normal_distribution<double> normal;
  for (double drift : {0.0, 0.003}) {
    MotionOptions options;
    options.memory = 0.98;  // a long memory, for a stable estimate
    MotionModel motion(options, kCentroid, kRadius);
    Rigid3 pose = Pose(0.1, {0, 0, 1}, {0.0, 0.0, 1.0});
    double sum = 0.0;
    int count = 0;
    for (int k = 0; k < 2000; ++k) {
      // Noise of 3 mm per step along the three axes in translation only, so that the drift's
      // share is known: per-axis variance 9e-6 against the drift's 9e-6 along x.
      const Eigen::Vector3d noise(0.003 * normal(random), 0.003 * normal(random),
                                  0.003 * normal(random));
      pose =
          pose * Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(drift, 0.0, 0.0) + noise);
      motion.Measure(pose, true);
      if (k >= 200) sum += motion.factor(), ++count;
    }
    const double mean = sum / count;
    SCOPED_TRACE("drift " + std::to_string(drift));
    // drift 0: 0; drift 3 mm: 9e-6 / (9e-6 + 27e-6) = 0.25.
    EXPECT_NEAR(mean, drift == 0.0 ? 0.0 : 0.25, 0.05);
  }
}

// The persistence is the factor's ramp (0 at or below 0.25, 1 at or above 0.75), and the step is
// scaled about the model's centroid: after spins about the centroid of 0.1 rad and then `second`
// (factor second / 0.1), the prediction turns by persistence * second about the centroid, which
// stays in place.
TEST(MotionModelTest, AScaledStepTurnsAboutTheCentroid) {
  const Rigid3 proxy_T_centroid(Eigen::Quaterniond::Identity(), kCentroid);
  auto spin = [&](double angle) {
    return proxy_T_centroid * Pose(angle, {0.3, 0, 1}, Eigen::Vector3d::Zero()) *
           proxy_T_centroid.Inverse();
  };
  for (const auto& [second, persistence] :
       {std::pair{0.05, 0.5}, {0.08, 1.0}, {0.02, 0.0}, {0.06, 0.7}}) {
    MotionModel motion({}, kCentroid, kRadius);
    Rigid3 pose = Pose(0.3, {0, 1, 1}, {0.05, 0.0, 1.0});
    motion.Measure(pose, true);
    motion.Measure(pose = pose * spin(0.1), true);
    motion.Measure(pose = pose * spin(second), true);
    SCOPED_TRACE("second spin " + std::to_string(second));
    EXPECT_NEAR(motion.factor(), second / 0.1, 1e-9);
    EXPECT_NEAR(motion.persistence(), persistence, 1e-9);
    const Rigid3 predicted = *motion.Predict();
    EXPECT_NEAR(AngleBetween(predicted, pose), persistence * second, 1e-9);
    EXPECT_LT((predicted * kCentroid - pose * kCentroid).norm(), 1e-12);
  }
}

// Coasting (no measurement) halves the step each frame, and a step across a coasted frame does
// not enter the persistence.
TEST(MotionModelTest, CoastingHalvesTheStep) {
  MotionOptions options;
  options.adaptive = false;
  MotionModel motion(options, kCentroid, kRadius);
  const Rigid3 step(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.008, 0.0, 0.0));
  Rigid3 pose = Pose(0.0, {0, 0, 1}, {0.0, 0.0, 1.0});
  motion.Measure(pose, true);
  motion.Measure(pose * step, true);
  const Rigid3 first = motion.Coast();
  EXPECT_NEAR(first.translation.x(), 0.008 + 0.004, 1e-12);
  const Rigid3 second = motion.Coast();
  EXPECT_NEAR(second.translation.x(), 0.012 + 0.002, 1e-12);
  motion.Reset();
  EXPECT_FALSE(motion.last());
  EXPECT_FALSE(motion.Predict());
}

TEST(MotionModelTest, TheRampMustRiseWithinZeroToOne) {
  for (const auto& [low, high, key] : {std::tuple{-0.1, 0.75, "stop_below"},
                                       {0.5, 0.4, "continue_above"},
                                       {0.25, 1.5, "continue_above"}}) {
    MotionOptions options;
    options.stop_below = low;
    options.continue_above = high;
    try {
      options.Validate("tracker.motion");
      FAIL() << "no error for " << low << " " << high;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("tracker.motion.") + key), std::string::npos)
          << e.what();
    }
  }
  MotionOptions step;
  step.stop_below = step.continue_above = 0.5;
  EXPECT_NO_THROW(step.Validate("tracker.motion"));
}

TEST(MotionModelTest, MemoryMustBeBelowOne) {
  for (double memory : {1.0, -0.1, std::nan("")}) {
    MotionOptions options;
    options.memory = memory;
    try {
      options.Validate("tracker.motion");
      FAIL() << "no error for " << memory;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("tracker.motion.memory"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("[0, 1)"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace mmh::track
