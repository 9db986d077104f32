// The viewer model: smooth motion has no artefacts, a jump does, blending hides it, and viewers
// prefer the better animation.
#include "people/viewer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/error.h"
#include "tests/test_util.h"

namespace mmh::people {
namespace {

using test_util::ErrorOf;

// A figure walking round a circle at constant speed, turning as it goes.
Trajectory Circle(int frames, double phase = 0) {
  Trajectory t;
  for (int i = 0; i < frames; ++i) {
    const double a = phase + 2 * std::numbers::pi * i / 300.0;
    t.timestamps.push_back(i / 30.0);
    t.poses.push_back(Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ())),
                             Eigen::Vector3d(0.1 * std::cos(a), 0.1 * std::sin(a), 0)));
  }
  return t;
}

TEST(ViewerTest, SmoothMotionHasNoArtefactsAndAJumpHas) {
  const ViewerOptions options;
  const Trajectory smooth = Circle(600);
  const std::vector<double> quality(600, 0.7);
  const Appeal clean = Appraise(smooth, quality, options);
  EXPECT_EQ(clean.artefact_frames, 0);
  EXPECT_NEAR(clean.appeal, 0.7, 1e-12);

  // A cut to another take 0.6 rad further round (6 cm away): a visible jump.
  Trajectory cut = smooth;
  const Trajectory other = Circle(600, 0.6);
  for (int i = 300; i < 600; ++i) cut.poses[i] = other.poses[i];
  const Appeal jumped = Appraise(cut, quality, options);
  EXPECT_GT(jumped.artefact_frames, 0);
  EXPECT_LT(jumped.appeal, clean.appeal - 0.02);
  const std::vector<double> trace = ArtefactTrace(cut, options);
  for (int i = 0; i < 600; ++i) {
    if (trace[i] > 0) EXPECT_NEAR(i, 300, options.smoothing) << i;
  }

  // The paper's blend (15 frames, lerp + slerp) makes the transition less visible.
  Trajectory blended = cut;
  for (int i = 293; i < 308; ++i) {
    const double w = (i - 292) / 16.0;
    blended.poses[i] = Interpolate(smooth.poses[i], other.poses[i], w);
  }
  EXPECT_LT(Appraise(blended, quality, options).artefacts, jumped.artefacts);
}

TEST(ViewerTest, ViewersPreferTheBetterAnimation) {
  const ViewerOptions options;
  const Trajectory motion = Circle(600);
  const Appeal good = Appraise(motion, std::vector<double>(600, 0.6), options);
  const Appeal fair = Appraise(motion, std::vector<double>(600, 0.55), options);
  int prefer_good = 0;
  for (int v = 0; v < 200; ++v) {
    const Viewer viewer = DrawViewer(options, 7, v);
    prefer_good +=
        Utility(good, viewer, options, 7, 2 * v) > Utility(fair, viewer, options, 7, 2 * v + 1);
  }
  // P(prefer) = Φ(0.05·b_q / (√2·σ)) for b_q ≈ 1 (0.58 at the calibrated σ = 0.179): within 4
  // binomial standard deviations of 200 viewings.
  const double p = 0.5 * std::erfc(-0.05 / (std::sqrt(2.0) * options.judgement_noise) / std::sqrt(2.0));
  EXPECT_NEAR(prefer_good, 200 * p, 4 * std::sqrt(200 * p * (1 - p)));
  EXPECT_GT(prefer_good, 100);  // the better animation is preferred more often than not
  // Reproducible per (seed, index) and (seed, viewing).
  EXPECT_EQ(DrawViewer(options, 7, 3).quality_weight, DrawViewer(options, 7, 3).quality_weight);
  const Viewer viewer = DrawViewer(options, 7, 3);
  EXPECT_EQ(Utility(good, viewer, options, 7, 5), Utility(good, viewer, options, 7, 5));
}

TEST(ViewerTest, CompositeQualityAndBadInput) {
  const std::vector<std::vector<double>> takes = {{0.1, 0.2, 0.3}, {0.9, 0.8}};
  const std::vector<int> take = {0, 0, 1, 1};
  const std::vector<int> frame = {0, 1, 0, 1};
  EXPECT_EQ(CompositeQuality(takes, take, frame), (std::vector<double>{0.1, 0.2, 0.9, 0.8}));
  const std::vector<int> bad_frame = {0, 1, 0, 2};
  EXPECT_NE(ErrorOf([&] { CompositeQuality(takes, take, bad_frame); }).find("composite frame 3"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              Appraise(Circle(10), std::vector<double>(9, 0.5), ViewerOptions{});
            }).find("one per frame (10)"),
            std::string::npos);
  ViewerOptions even;
  even.smoothing = 4;
  EXPECT_NE(ErrorOf([&] { even.Validate("viewer"); }).find("viewer.smoothing"), std::string::npos);
}

}  // namespace
}  // namespace mmh::people
