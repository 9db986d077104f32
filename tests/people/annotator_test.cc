// The annotator: the delay recovered by cross-correlation is the configured one, the hand is
// smooth and speed-limited, lapses hold the block, and the judgement follows the quality.
#include "people/annotator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/error.h"
#include "people/performance.h"
#include "tests/test_util.h"

namespace mmh::people {
namespace {

using test_util::ErrorOf;

std::vector<double> TakeQuality(double skill, std::uint64_t seed) {
  static const Story story =
      LoadStory(std::string(MMH_SOURCE_DIR) + "/configs/stories/soldier.json");
  AnimatorProfile animator;
  animator.skill = skill;
  return PerformTake(story, 0, animator, 0, PerformanceOptions{}, seed).quality.quality;
}

AnnotatorProfile Ideal() {
  AnnotatorProfile p;
  p.delay_variation = 0;
  p.opinion_noise = 0;
  p.tremor = 0;
  p.lapse_rate = 0;
  p.hand_frequency = 300;
  p.max_speed = 1e6;
  return p;
}

TEST(AnnotatorTest, CrossCorrelationRecoversTheConfiguredDelay) {
  const std::vector<double> quality = TakeQuality(0.4, 11);
  AnnotatorOptions options;
  options.substeps = 64;
  for (const double delay : {0.25, 0.30, 0.35}) {
    AnnotatorProfile p = Ideal();
    p.reaction_delay = delay;
    const AnnotationSession s = AnnotateTake(quality, p, options, 3);
    const double lag = CrossCorrelationLag(s.judgement, s.slider, 30);
    // A 300 rad/s hand adds 2/ω = 0.2 frames.
    EXPECT_NEAR(lag, delay * 30 + 2.0 / 300 * 30, 0.3) << "delay " << delay;
  }
}

TEST(AnnotatorTest, DefaultHandLagsByTheDelayPlusTheHandsResponse) {
  // With the default hand the slider lags the judgement by the reaction delay plus between 1/ω
  // (the impulse response's peak, for abrupt changes) and 2/ω (its centroid, for slow ones).
  AnnotatorProfile p;
  p.lapse_rate = 0;
  for (const std::uint64_t seed : {1, 2, 3}) {
    const std::vector<double> quality = TakeQuality(0.3, seed);
    const AnnotationSession s = AnnotateTake(quality, p, AnnotatorOptions{}, seed);
    const double lag = CrossCorrelationLag(s.judgement, s.slider, 30);
    EXPECT_GE(lag, (p.reaction_delay - p.delay_variation + 1 / p.hand_frequency) * 30 - 0.5);
    EXPECT_LE(lag, (p.reaction_delay + p.delay_variation + 2 / p.hand_frequency) * 30 + 0.5);
    // The delay itself wanders inside d̄ ± δ.
    for (const double d : s.delay) {
      ASSERT_GE(d, p.reaction_delay - p.delay_variation - 1e-12);
      ASSERT_LE(d, p.reaction_delay + p.delay_variation + 1e-12);
    }
  }
}

TEST(AnnotatorTest, HandIsSmoothSpeedLimitedAndInRange) {
  const std::vector<double> quality = TakeQuality(0.2, 5);
  AnnotatorProfile p;
  p.tremor = 0;
  p.max_speed = 12;
  p.taste_gain = 40;  // decisive: hits the end stops
  const AnnotationSession s = AnnotateTake(quality, p, AnnotatorOptions{}, 9);
  ASSERT_EQ(s.slider.size(), quality.size());
  for (std::size_t i = 1; i < s.slider.size(); ++i) {
    ASSERT_LE(std::abs(s.slider[i] - s.slider[i - 1]), p.max_speed / 30 + 1e-9) << i;
    ASSERT_LE(std::abs(s.slider[i]), 5.0);
  }
  EXPECT_GT(s.clipped_fraction, 0.0);
  // Deterministic per seed.
  EXPECT_EQ(AnnotateTake(quality, p, AnnotatorOptions{}, 9).slider, s.slider);
  EXPECT_NE(AnnotateTake(quality, p, AnnotatorOptions{}, 10).slider, s.slider);
}

TEST(AnnotatorTest, LapsesHoldTheBlock) {
  const std::vector<double> quality = TakeQuality(0.2, 6);
  AnnotatorProfile p;
  p.tremor = 0;
  p.lapse_rate = 6;
  p.lapse_seconds = 2;
  const AnnotationSession s = AnnotateTake(quality, p, AnnotatorOptions{}, 4);
  int checked = 0;
  for (const auto& [first, last] : s.lapses) {
    if (last - first < 30) continue;
    // After the hand has settled (0.5 s), the block stays put until the lapse ends.
    for (int i = first + 15; i <= last; ++i) ASSERT_NEAR(s.slider[i], s.slider[last], 0.02);
    ++checked;
  }
  EXPECT_GT(checked, 0);
}

TEST(AnnotatorTest, JudgementFollowsTheQuality) {
  const std::vector<double> quality = TakeQuality(0.3, 8);
  const AnnotationSession s = AnnotateTake(quality, AnnotatorProfile{}, AnnotatorOptions{}, 1);
  double mq = 0, mj = 0;
  const double n = quality.size();
  for (std::size_t i = 0; i < quality.size(); ++i) mq += quality[i] / n, mj += s.judgement[i] / n;
  double qq = 0, jj = 0, qj = 0;
  for (std::size_t i = 0; i < quality.size(); ++i) {
    qq += (quality[i] - mq) * (quality[i] - mq);
    jj += (s.judgement[i] - mj) * (s.judgement[i] - mj);
    qj += (quality[i] - mq) * (s.judgement[i] - mj);
  }
  EXPECT_GT(qj / std::sqrt(qq * jj), 0.7);
}

TEST(AnnotatorTest, BadInput) {
  std::vector<double> quality(100, 0.5);
  quality[7] = std::nan("");
  EXPECT_NE(ErrorOf([&] {
              AnnotateTake(quality, AnnotatorProfile{}, AnnotatorOptions{}, 1);
            }).find("quality[7]"),
            std::string::npos);
  AnnotatorProfile p;
  p.delay_variation = 0.5;
  EXPECT_NE(ErrorOf([&] { AnnotateTake({}, p, AnnotatorOptions{}, 1); }).find("delay_variation"),
            std::string::npos);
  AnnotatorOptions o;
  o.start_value = 7;
  EXPECT_NE(
      ErrorOf([&] { AnnotateTake({}, AnnotatorProfile{}, o, 1); }).find("annotator.start_value"),
      std::string::npos);
}

}  // namespace
}  // namespace mmh::people

namespace mmh::people {
namespace {

// The dead band h (intermittent control): the hand moves only when the opinion has left the
// block by more than h, so the block dwells at a few positions (moving less than 0.001 slider
// units a frame); h = 0 is the continuous pursuit.
TEST(AnnotatorTest, MoveThresholdMakesTheBlockDwell) {
  const std::vector<double> quality = TakeQuality(0.4, 5);
  AnnotatorProfile p;  // with opinion noise and tremor
  p.tremor = 0;        // so that a resting block is exactly still
  const AnnotationSession continuous = AnnotateTake(quality, p, AnnotatorOptions{}, 3);
  p.move_threshold = 2.0;
  const AnnotationSession dwelling = AnnotateTake(quality, p, AnnotatorOptions{}, 3);
  auto still_share = [](const std::vector<double>& x) {
    int still = 0;
    for (std::size_t i = 1; i < x.size(); ++i) still += std::abs(x[i] - x[i - 1]) < 1e-3;
    return static_cast<double>(still) / (x.size() - 1);
  };
  EXPECT_LT(still_share(continuous.slider), 0.3) << still_share(continuous.slider);
  EXPECT_GT(still_share(dwelling.slider), 0.6) << still_share(dwelling.slider);
  // Same judgement (the threshold acts on the hand only), and the block still follows it.
  EXPECT_EQ(continuous.judgement, dwelling.judgement);
  double error = 0;
  for (std::size_t i = 0; i < quality.size(); ++i) {
    error += std::abs(dwelling.slider[i] - continuous.slider[i]);
  }
  EXPECT_LT(error / quality.size(), 2.0);
  // Out of range: a clear error.
  p.move_threshold = -1;
  EXPECT_NE(ErrorOf([&] { p.Validate("annotator"); }).find("annotator.move_threshold"),
            std::string::npos);
}

}  // namespace
}  // namespace mmh::people
