// The trajectory smoother against Savitzky and Golay's (1964) tabulated weights, exact polynomial
// motion, seeded noise around a known smooth motion, and its run breaks.
#include "track/trajectory_smoother.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "tests/test_util.h"

namespace mmh::track {
namespace {

using test_util::ErrorOf;
using ::testing::HasSubstr;

constexpr double kFrameRate = 30.0;

std::vector<double> Timestamps(int frames) {
  std::vector<double> t(frames);
  for (int i = 0; i < frames; ++i) t[i] = 1.5 + i / kFrameRate;
  return t;
}

Eigen::Quaterniond Turn(double angle, const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis.normalized()));
}

// A smooth motion: the proxy walks and swings about a tilted axis, as in a take [s].
Rigid3 Motion(double t) {
  return Rigid3(Turn(0.6 * std::sin(1.3 * t), Eigen::Vector3d(0.2, 1, 0.3)) *
                    Turn(0.4 * t, Eigen::Vector3d(0, 0, 1)),
                Eigen::Vector3d(0.1 * std::sin(0.9 * t), 0.05 * t, 1.1 + 0.02 * std::cos(2 * t)));
}

// A single 1 mm step in x at one frame of a resting trajectory is spread with the 9-point
// quadratic Savitzky-Golay weights (-21, 14, 39, 54, 59, 54, 39, 14, -21) / 231.
TEST(TrajectorySmootherTest, AnImpulseGetsSavitzkyGolaysTabulatedWeights) {
  const int frames = 21, at = 10;
  std::vector<Rigid3> poses(frames, Rigid3(Eigen::Quaterniond::Identity(), {0, 0, 1}));
  poses[at].translation.x() += 0.001;
  const std::vector<bool> measured(frames, true);
  TrajectorySmootherOptions options;  // half_window 4, degree 2
  const TrajectorySmootherSummary summary =
      SmoothTrajectory(Timestamps(frames), measured, options, &poses);
  const double weights[] = {-21, 14, 39, 54, 59, 54, 39, 14, -21};
  for (int i = 0; i < frames; ++i) {
    const double expected = std::abs(i - at) <= 4 ? 0.001 * weights[i - at + 4] / 231 : 0.0;
    EXPECT_NEAR(poses[i].translation.x(), expected, 1e-15) << i;
    EXPECT_NEAR(poses[i].translation.z(), 1.0, 1e-15) << i;
    EXPECT_LT(RotationAngle(poses[i].rotation, Eigen::Quaterniond::Identity()), 1e-15) << i;
  }
  EXPECT_EQ(summary.measured, frames);
  EXPECT_EQ(summary.runs, 1);
  EXPECT_EQ(summary.breaks, 0);
}

// A parabola is kept exactly by degree 2 (angle and position quadratic in time about fixed axes:
// the tangent-space values are exactly quadratic), also at the run's ends; a line by degree 1.
TEST(TrajectorySmootherTest, KeepsMotionUpToItsDegreeExactly) {
  for (int degree : {1, 2}) {
    const int frames = 40;
    const std::vector<double> t = Timestamps(frames);
    const Eigen::Vector3d axis(0.3, -0.5, 0.8);
    std::vector<Rigid3> truth(frames);
    for (int i = 0; i < frames; ++i) {
      const double s = t[i] - 2;
      const double quadratic = degree == 2 ? s * s : 0.0;
      truth[i] = Rigid3(Turn(0.2 + 0.9 * s + 1.1 * quadratic, axis) * Turn(0.4, {1, 0, 0}),
                        Eigen::Vector3d(0.05 * s - 0.3 * quadratic, 0.02, 1 + 0.1 * quadratic));
    }
    std::vector<Rigid3> poses = truth;
    TrajectorySmootherOptions options;
    options.degree = degree;
    options.half_window = 5;
    SmoothTrajectory(t, std::vector<bool>(frames, true), options, &poses);
    for (int i = 0; i < frames; ++i) {
      EXPECT_LT(RotationAngle(poses[i].rotation, truth[i].rotation), 1e-12) << degree << " " << i;
      EXPECT_LT((poses[i].translation - truth[i].translation).norm(), 1e-12) << degree << " " << i;
    }
  }
}

// Seeded noise of a story take's size (0.8 deg, 1.5 mm per frame, independent from frame to
// frame) around the smooth motion: the smoothed poses are nearer the motion, by about the
// weights' noise gain sqrt(59 / 231) = 0.51 away from the ends.
TEST(TrajectorySmootherTest, HalvesIndependentNoiseAroundASmoothMotion) {
  const int frames = 600;
  const std::vector<double> t = Timestamps(frames);
  std::mt19937_64 random(7);
  std::normal_distribution<double> normal;
  std::vector<Rigid3> truth(frames), poses(frames);
  for (int i = 0; i < frames; ++i) {
    truth[i] = Motion(t[i]);
    const Eigen::Vector3d turn(normal(random), normal(random), normal(random));
    const Eigen::Vector3d shift(normal(random), normal(random), normal(random));
    // Rotation vector and shift of 0.8 deg and 1.5 mm RMS.
    poses[i] =
        Rigid3(Turn(0.8 * M_PI / 180 * turn.norm() / std::sqrt(3.0), turn) * truth[i].rotation,
               truth[i].translation + 0.0015 / std::sqrt(3.0) * shift);
  }
  auto rms = [&](const std::vector<Rigid3>& p, bool rotation) {
    double sum = 0;
    for (int i = 0; i < frames; ++i) {
      sum += rotation ? std::pow(RotationAngle(p[i].rotation, truth[i].rotation), 2)
                      : (p[i].translation - truth[i].translation).squaredNorm();
    }
    return std::sqrt(sum / frames);
  };
  const double rotation_before = rms(poses, true), translation_before = rms(poses, false);
  const TrajectorySmootherSummary summary =
      SmoothTrajectory(t, std::vector<bool>(frames, true), TrajectorySmootherOptions(), &poses);
  const double rotation_ratio = rms(poses, true) / rotation_before;
  const double translation_ratio = rms(poses, false) / translation_before;
  std::printf("noise kept: rotation %.3f, translation %.3f; %d runs\n", rotation_ratio,
              translation_ratio, summary.runs);
  EXPECT_EQ(summary.runs, 1);
  EXPECT_GT(rotation_ratio, 0.45);
  EXPECT_LT(rotation_ratio, 0.6);
  EXPECT_GT(translation_ratio, 0.45);
  EXPECT_LT(translation_ratio, 0.6);
}

// A half turn (a switch between twins), a lost frame and a predicted frame end runs: each run is
// smoothed on its own, as if the others did not exist, and frames not measured are unchanged.
TEST(TrajectorySmootherTest, RunsEndAtJumpsAndAtFramesNotMeasured) {
  const int frames = 60;
  const std::vector<double> t = Timestamps(frames);
  std::mt19937_64 random(3);
  std::normal_distribution<double> normal(0.0, 0.001);
  std::vector<Rigid3> poses(frames);
  for (int i = 0; i < frames; ++i) {
    poses[i] = Motion(t[i]);
    poses[i].translation += Eigen::Vector3d(normal(random), normal(random), normal(random));
    // From frame 20 on the track is in the twin, half a turn about the proxy's z.
    if (i >= 20) poses[i].rotation = poses[i].rotation * Turn(M_PI, {0, 0, 1});
  }
  // Frame 30 slides 2 cm up (a recovered slide from frame 31 on).
  poses[30].translation.z() -= 0.02;
  std::vector<bool> measured(frames, true);
  measured[41] = false;  // lost
  measured[50] = false;  // predicted
  std::vector<Rigid3> smoothed = poses;
  const TrajectorySmootherSummary summary =
      SmoothTrajectory(t, measured, TrajectorySmootherOptions(), &smoothed);
  EXPECT_EQ(summary.runs, 6);  // 0-19, 20-29, 30, 31-40, 42-49, 51-59
  EXPECT_EQ(summary.breaks, 3);
  EXPECT_EQ(summary.measured, frames - 3);  // all but the two not measured and the lone frame 30
  const int runs[][2] = {{0, 19}, {20, 29}, {30, 30}, {31, 40}, {42, 49}, {51, 59}};
  for (const auto& run : runs) {
    const int n = run[1] - run[0] + 1;
    std::vector<Rigid3> alone(poses.begin() + run[0], poses.begin() + run[1] + 1);
    SmoothTrajectory(std::vector<double>(t.begin() + run[0], t.begin() + run[1] + 1),
                     std::vector<bool>(n, true), TrajectorySmootherOptions(), &alone);
    for (int i = 0; i < n; ++i) {
      EXPECT_LT(RotationAngle(smoothed[run[0] + i].rotation, alone[i].rotation), 1e-14);
      EXPECT_LT((smoothed[run[0] + i].translation - alone[i].translation).norm(), 1e-15);
    }
  }
  for (int i : {30, 41, 50}) {
    EXPECT_EQ(smoothed[i].translation, poses[i].translation) << i;
    EXPECT_EQ(smoothed[i].rotation.coeffs(), poses[i].rotation.coeffs()) << i;
  }
}

TEST(TrajectorySmootherTest, DisabledChangesNothing) {
  std::vector<Rigid3> poses = {Motion(0), Motion(0.1), Motion(0.2), Motion(0.5), Motion(0.6)};
  poses[2].translation.x() += 0.003;
  const std::vector<Rigid3> before = poses;
  TrajectorySmootherOptions options;
  options.enabled = false;
  SmoothTrajectory({0, 0.1, 0.2, 0.5, 0.6}, std::vector<bool>(5, true), options, &poses);
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(poses[i].translation, before[i].translation);
  }
}

TEST(TrajectorySmootherTest, BadOptionsAndLengthsAreErrors) {
  TrajectorySmootherOptions options;
  options.degree = 3;
  EXPECT_THAT(ErrorOf([&] { options.Validate("smoothing"); }),
              HasSubstr("smoothing.degree: got 3, expected 1 (line) or 2 (parabola)"));
  options.degree = 2;
  options.half_window = 2;
  EXPECT_THAT(ErrorOf([&] { options.Validate("smoothing"); }),
              HasSubstr("smoothing.half_window: got 2, expected an integer from degree + 1 = 3"));
  options.half_window = 4;
  options.break_translation = std::nan("");
  EXPECT_THAT(ErrorOf([&] { options.Validate("smoothing"); }),
              HasSubstr("smoothing.break_translation"));
  std::vector<Rigid3> poses(3);
  EXPECT_THAT(ErrorOf([&] {
                SmoothTrajectory({0, 1}, {true, true, true}, TrajectorySmootherOptions(), &poses);
              }),
              HasSubstr("3 poses, 2 timestamps and 3 measured flags"));
}

}  // namespace
}  // namespace mmh::track
