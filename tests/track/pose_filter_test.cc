// The tracker's output filter (track/pose_filter.h) against the exponential smoother it reduces to
// with the betas at 0 (written here from its definition), the steady-state lag of that smoother
// on a ramp, and the noise reduction of a first-order low-pass on white noise.
#include "track/pose_filter.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <tuple>

#include "core/error.h"

namespace mmh::track {
namespace {

constexpr double kDt = 1.0 / 30.0;

// alpha of an exponential smoother with cutoff f [Hz] at the frame period kDt.
double Alpha(double cutoff_hz) {
  return 1.0 / (1.0 + 1.0 / (2 * std::numbers::pi * cutoff_hz * kDt));
}

Rigid3 AboutZ(double angle, const Eigen::Vector3d& translation) {
  return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ())),
                translation);
}

PoseFilterOptions Fixed(double cutoff_hz) {
  PoseFilterOptions options;
  options.enabled = true;
  options.min_cutoff_hz = cutoff_hz;
  options.translation_beta = 0;
  options.rotation_beta = 0;
  return options;
}

TEST(PoseFilterTest, TheFirstPoseAndARestartPassThrough) {
  PoseFilter filter(Fixed(1.0));
  const Rigid3 a = AboutZ(0.3, {0.1, 0.2, 0.9});
  const Rigid3 b = AboutZ(-0.2, {0.0, 0.1, 0.8});
  EXPECT_TRUE(filter.Filter(0.0, a).translation.isApprox(a.translation));
  EXPECT_FALSE(filter.Filter(kDt, b).translation.isApprox(b.translation));
  filter.Reset();
  EXPECT_EQ(filter.Filter(2 * kDt, b).translation, b.translation);
  // A timestamp that does not advance restarts it too.
  EXPECT_EQ(filter.Filter(2 * kDt, a).translation, a.translation);
  EXPECT_NEAR(RotationAngle(filter.Filter(2 * kDt, a).rotation, a.rotation), 0.0, 1e-12);
}

// Betas at 0: x_hat <- x_hat + alpha (x - x_hat) with alpha of min_cutoff_hz, and about a fixed
// axis the rotation angle follows the same recursion.
TEST(PoseFilterTest, WithoutBetaItIsTheExponentialSmoother) {
  PoseFilter filter(Fixed(1.5));
  const double alpha = Alpha(1.5);
  std::mt19937_64 random(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  Eigen::Vector3d x_hat(0.1, 0.0, 0.8);
  double angle_hat = 0.4;
  filter.Filter(0.0, AboutZ(angle_hat, x_hat));
  for (int i = 1; i < 300; ++i) {
    const Eigen::Vector3d x = Eigen::Vector3d(0.1, 0.0, 0.8) +
                              0.002 * Eigen::Vector3d(noise(random), noise(random), noise(random));
    const double angle = 0.4 + 0.02 * noise(random);
    x_hat += alpha * (x - x_hat);
    angle_hat += alpha * (angle - angle_hat);
    const Rigid3 out = filter.Filter(i * kDt, AboutZ(angle, x));
    ASSERT_NEAR((out.translation - x_hat).norm(), 0.0, 1e-12) << i;
    ASSERT_NEAR(RotationAngle(out.rotation, AboutZ(angle_hat, Eigen::Vector3d::Zero()).rotation),
                0.0, 1e-9)
        << i;
  }
}

// White noise through x_hat <- (1 - a) x_hat + a x keeps a / (2 - a) of its variance.
TEST(PoseFilterTest, AStillPoseKeepsTheSmoothersShareOfItsNoise) {
  PoseFilterOptions options;  // the defaults, betas included
  options.enabled = true;
  PoseFilter filter(options);
  std::mt19937_64 random(11);
  std::normal_distribution<double> noise(0.0, 1.0);
  // Per axis: structured-light jitter (1.5 deg, 1.6 mm; docs/study.md).
  const double sd_translation = 0.0016, sd_angle = 0.026;
  double sum_t = 0, sum_r = 0;
  int n = 0;
  for (int i = 0; i < 6000; ++i) {
    const Eigen::Vector3d axis(noise(random), noise(random), noise(random));
    const Rigid3 measured(
        Eigen::Quaterniond(Eigen::AngleAxisd(sd_angle * axis.norm(), axis.normalized())),
        Eigen::Vector3d(0, 0, 0.8) +
            sd_translation * Eigen::Vector3d(noise(random), noise(random), noise(random)));
    const Rigid3 out = filter.Filter(i * kDt, measured);
    if (i < 100) continue;
    sum_t += (out.translation - Eigen::Vector3d(0, 0, 0.8)).squaredNorm() / 3;
    sum_r += std::pow(RotationAngle(out.rotation, Eigen::Quaterniond::Identity()), 2) / 3;
    ++n;
  }
  const double a = Alpha(options.min_cutoff_hz);
  const double still_ratio = std::sqrt(a / (2 - a));  // 0.25 at 1 Hz and 30 frames/s
  // The noise's own speed opens the cutoff a little above min_cutoff_hz: at most 1.5 times the
  // still smoother's share, and far below the raw noise.
  const double ratio_t = std::sqrt(sum_t / n) / sd_translation;
  const double ratio_r = std::sqrt(sum_r / n) / sd_angle;
  EXPECT_GE(ratio_t, still_ratio * 0.95);
  EXPECT_LE(ratio_t, still_ratio * 1.5);
  EXPECT_GE(ratio_r, still_ratio * 0.95);
  EXPECT_LE(ratio_r, still_ratio * 1.5);
}

// A ramp at speed v: the exponential smoother settles at a lag L = v dt (1 - a) / a = v / (2 pi f).
// With a beta the speed is estimated from the raw pose and the last filtered one (the 1 euro
// filter's definition), so in the steady state it is (v dt + L) / dt and f = f_min + beta (v +
// L / dt): 2 pi beta / dt L^2 + 2 pi (f_min + beta v) L - v = 0, a shorter lag.
TEST(PoseFilterTest, ARampLagsByTheSmoothersLagAndLessWithBeta) {
  const double speed = 0.1, turn = 1.0;  // [m/s], [rad/s]
  auto lags = [&](const PoseFilterOptions& options) {
    PoseFilter filter(options);
    Rigid3 out;
    double t = 0;
    for (int i = 0; i < 900; ++i) {
      t = i * kDt;
      out = filter.Filter(t, AboutZ(turn * t, {speed * t, 0, 0.8}));
    }
    return std::pair{
        speed * t - out.translation.x(),
        RotationAngle(out.rotation, AboutZ(turn * t, Eigen::Vector3d::Zero()).rotation)};
  };
  const double a = Alpha(1.0);
  const auto [lag_t, lag_r] = lags(Fixed(1.0));
  EXPECT_NEAR(lag_t, speed * kDt * (1 - a) / a, 1e-9);
  EXPECT_NEAR(lag_r, turn * kDt * (1 - a) / a, 1e-9);
  auto steady_lag = [](double v, double f_min, double beta) {
    const double q = 2 * std::numbers::pi * beta / kDt;
    const double p = 2 * std::numbers::pi * (f_min + beta * v);
    return (-p + std::sqrt(p * p + 4 * q * v)) / (2 * q);
  };
  PoseFilterOptions adaptive;
  adaptive.enabled = true;
  const auto [adaptive_t, adaptive_r] = lags(adaptive);
  EXPECT_NEAR(adaptive_t, steady_lag(speed, adaptive.min_cutoff_hz, adaptive.translation_beta),
              1e-7);
  EXPECT_NEAR(adaptive_r, steady_lag(turn, adaptive.min_cutoff_hz, adaptive.rotation_beta), 1e-6);
  EXPECT_LT(adaptive_t, lag_t / 2);
  EXPECT_LT(adaptive_r, lag_r / 2);
}

TEST(PoseFilterTest, BadOptionsNameTheKeyAndTheValue) {
  for (const auto& [field, key, value] :
       {std::tuple{&PoseFilterOptions::min_cutoff_hz, "min_cutoff_hz", 0.0},
        std::tuple{&PoseFilterOptions::derivative_cutoff_hz, "derivative_cutoff_hz", -1.0},
        std::tuple{&PoseFilterOptions::translation_beta, "translation_beta", -0.5},
        std::tuple{&PoseFilterOptions::rotation_beta, "rotation_beta", std::nan("")}}) {
    PoseFilterOptions options;
    options.*field = value;
    try {
      options.Validate("tracker.output_filter");
      ADD_FAILURE() << "no error for " << key;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("tracker.output_filter.") + key),
                std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace mmh::track
