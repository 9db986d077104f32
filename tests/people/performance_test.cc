// Performances: deterministic, on the story's path, better with skill and over takes, flaws where
// their beats are, and a latent quality that is measured from the motion.
#include "people/performance.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "core/error.h"
#include "core/options.h"
#include "tests/test_util.h"

namespace mmh::people {
namespace {

using test_util::ErrorOf;

const Story& Soldier() {
  static const Story story =
      LoadStory(std::string(MMH_SOURCE_DIR) + "/configs/stories/soldier.json");
  return story;
}

AnimatorProfile WithSkill(double skill) {
  AnimatorProfile a;
  a.skill = skill;
  return a;
}

TEST(PerformanceTest, DeterministicPerSeedAndDifferentAcrossSeedsAndTakes) {
  const PerformanceOptions options;
  const PerformedTake a = PerformTake(Soldier(), 0, WithSkill(0.5), 1, options, 42);
  const PerformedTake b = PerformTake(Soldier(), 0, WithSkill(0.5), 1, options, 42);
  ASSERT_EQ(a.frames(), b.frames());
  for (int i = 0; i < a.frames(); ++i) {
    ASSERT_EQ(a.table_T_proxy.poses[i].translation, b.table_T_proxy.poses[i].translation);
    ASSERT_EQ(a.table_T_proxy.poses[i].rotation.coeffs(),
              b.table_T_proxy.poses[i].rotation.coeffs());
    ASSERT_EQ(a.quality.quality[i], b.quality.quality[i]);
  }
  const PerformedTake c = PerformTake(Soldier(), 0, WithSkill(0.5), 1, options, 43);
  const PerformedTake d = PerformTake(Soldier(), 0, WithSkill(0.5), 2, options, 42);
  // Takes differ in length.
  EXPECT_NE(a.frames(), c.frames());
  EXPECT_NE(a.frames(), d.frames());
  // About 68 s at 30 fps, give or take the animator's timing.
  EXPECT_GT(a.frames(), 1500);
  EXPECT_LT(a.frames(), 3000);
  EXPECT_DOUBLE_EQ(a.table_T_proxy.timestamps[30], 1.0);
}

TEST(PerformanceTest, TakesFollowTheStoryPath) {
  const PerformanceOptions options;
  const StoryObject& o = Soldier().objects[0];
  for (const double skill : {0.2, 0.9}) {
    const PerformedTake take = PerformTake(Soldier(), 0, WithSkill(skill), 0, options, 7);
    std::vector<double> distance;
    for (int i = 0; i < take.frames(); ++i) {
      bool flawed = false;
      for (const Flaw& f : take.flaws) flawed = flawed || (i >= f.first_frame && i <= f.last_frame);
      if (flawed) continue;
      const std::vector<Eigen::Vector2d> path = o.BeatPolyline(take.script_beat[i]);
      distance.push_back(
          DistanceToPolyline(path, take.table_T_proxy.poses[i].translation.head<2>()));
    }
    std::sort(distance.begin(), distance.end());
    const double median = distance[distance.size() / 2];
    const double p99 = distance[distance.size() * 99 / 100];
    // The tolerance is the style's: the wander and tremor amplitudes at this skill, plus the
    // gait's smoothing of corners.
    const double wander =
        options.wander_unskilled + (options.wander_skilled - options.wander_unskilled) * take.skill;
    const double tremor =
        options.tremor_unskilled + (options.tremor_skilled - options.tremor_unskilled) * take.skill;
    EXPECT_LT(median, 1.5 * (wander + tremor)) << "skill " << skill;
    EXPECT_LT(p99, 4.0 * (wander + tremor) + 0.01) << "skill " << skill;
    // Every frame stays on the table top.
    for (const Rigid3& pose : take.table_T_proxy.poses) {
      EXPECT_LT(std::abs(pose.translation.x()), 0.6);
      EXPECT_LT(std::abs(pose.translation.y()), 0.4);
      EXPECT_GT(pose.translation.z(), -0.005);
    }
  }
}

TEST(PerformanceTest, SkillRaisesQualityAndLaterTakesAreBetter) {
  const PerformanceOptions options;
  double mean[3] = {0, 0, 0};
  double by_take[3] = {0, 0, 0};
  const double skills[3] = {0.1, 0.5, 0.9};
  const int seeds = 6;
  for (int s = 0; s < 3; ++s) {
    for (int seed = 0; seed < seeds; ++seed) {
      for (int take = 0; take < 3; ++take) {
        const double q =
            PerformTake(Soldier(), 0, WithSkill(skills[s]), take, options, seed).MeanQuality();
        mean[s] += q / (3 * seeds);
        by_take[take] += q / (3 * seeds);
      }
    }
  }
  EXPECT_LT(mean[0] + 0.1, mean[1]);
  EXPECT_LT(mean[1] + 0.1, mean[2]);
  EXPECT_LT(by_take[0], by_take[1]);
  EXPECT_LT(by_take[1], by_take[2]);
}

TEST(PerformanceTest, FlawsLandOnTheirBeatsAndLowerTheQualityThere) {
  PerformanceOptions options;
  options.hesitation_rate = options.wrong_direction_rate = options.off_area_rate = 0.5;
  options.botched_fall_rate = 1.0;
  int checked = 0;
  for (int seed = 0; seed < 6; ++seed) {
    const PerformedTake take = PerformTake(Soldier(), 0, WithSkill(0.3), 0, options, seed);
    ASSERT_FALSE(take.flaws.empty());
    for (const Flaw& flaw : take.flaws) {
      ASSERT_LE(flaw.first_frame, flaw.last_frame);
      for (int i = flaw.first_frame; i <= flaw.last_frame; ++i) {
        ASSERT_EQ(take.script_beat[i], flaw.beat) << mmh::EnumName(flaw.kind);
      }
      // Mean quality over the flaw's frames against the same beat performed without the flaw by
      // a take of the same animator with no flaws at all.
      double flawed = 0;
      for (int i = flaw.first_frame; i <= flaw.last_frame; ++i) flawed += take.quality.quality[i];
      flawed /= flaw.last_frame - flaw.first_frame + 1;
      PerformanceOptions clean = options;
      clean.hesitation_rate = clean.out_of_order_rate = clean.missed_rate = 0;
      clean.wrong_direction_rate = clean.botched_fall_rate = clean.off_area_rate = 0;
      const PerformedTake reference = PerformTake(Soldier(), 0, WithSkill(0.3), 0, clean, seed);
      double good = 0;
      int count = 0;
      for (int i = 0; i < reference.frames(); ++i) {
        if (reference.script_beat[i] == flaw.beat) good += reference.quality.quality[i], ++count;
      }
      ASSERT_GT(count, 0);
      EXPECT_LT(flawed, good / count)
          << mmh::EnumName(flaw.kind) << " at beat " << flaw.beat << " seed " << seed;
      ++checked;
    }
  }
  EXPECT_GT(checked, 10);
}

TEST(PerformanceTest, QualityIsMeasuredFromTheMotion) {
  const PerformanceOptions options;
  const PerformedTake take = PerformTake(Soldier(), 0, WithSkill(0.8), 2, options, 3);
  // The same motion measured again gives the same quality.
  const QualityTrace again = MeasureQuality(Soldier().objects[0], take, take.table_T_proxy,
                                            options.quality, options.frame_rate);
  EXPECT_EQ(again.quality, take.quality.quality);
  // Push a stretch of the first march (along x in front of the castle) 6 cm off the path:
  // quality drops there and only near there.
  Trajectory moved = take.table_T_proxy;
  for (int i = 30; i < 130; ++i) moved.poses[i].translation.y() -= 0.06;
  const QualityTrace changed =
      MeasureQuality(Soldier().objects[0], take, moved, options.quality, options.frame_rate);
  double before = 0, after = 0;
  for (int i = 40; i < 120; ++i) before += take.quality.quality[i], after += changed.quality[i];
  EXPECT_LT(after, 0.3 * before);
  for (int i = 200; i < take.frames(); ++i) ASSERT_EQ(changed.quality[i], take.quality.quality[i]);
  for (const double q : changed.quality) ASSERT_TRUE(q >= 0 && q <= 1);
}

TEST(PerformanceTest, LayeredTakesHaveTheMontagesLengthAndHitTheirMarkers) {
  const Story story =
      LoadStory(std::string(MMH_SOURCE_DIR) + "/configs/stories/mario_monster.json");
  const PerformanceOptions options;
  const PerformedTake monster = PerformTake(story, 0, WithSkill(0.9), 0, options, 5);
  const std::vector<Trajectory> montages = {monster.table_T_proxy};
  const int frames = monster.frames();
  for (const int take : {0, 1, 2}) {
    const PerformedTake mario =
        PerformLayeredTake(story, 1, WithSkill(0.9), take, frames, montages, options, 5);
    EXPECT_EQ(mario.frames(), frames);
    ASSERT_EQ(mario.markers.size(), 1u);
    const int marker = mario.markers[0];
    EXPECT_GE(marker, 0);
    EXPECT_LT(marker, frames);
    // A skilled animator lands on the monster's head close to the marker's time and place.
    double best = 1e9;
    int best_frame = 0;
    for (int i = 0; i < frames; ++i) {
      const Eigen::Vector3d head = monster.table_T_proxy.poses[i].translation +
                                   Eigen::Vector3d(0, 0, story.objects[0].height);
      const double d = (mario.table_T_proxy.poses[i].translation - head).norm();
      if (d < best) best = d, best_frame = i;
    }
    EXPECT_LT(best, 0.03) << "take " << take;
    EXPECT_LT(std::abs(best_frame - marker), 30) << "take " << take;
  }
  // Objects with hit beats cannot be recorded alone; montages must have the right length.
  EXPECT_NE(ErrorOf([&] {
              PerformTake(story, 1, WithSkill(0.5), 0, options, 1);
            }).find("PerformLayeredTake"),
            std::string::npos);
  const std::vector<Trajectory> short_montage = {Trajectory{}};
  EXPECT_NE(ErrorOf([&] {
              PerformLayeredTake(story, 1, WithSkill(0.5), 0, frames, short_montage, options, 1);
            }).find("montage of \"monster\""),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { PerformTake(story, 5, WithSkill(0.5), 0, options, 1); }).find("object"),
            std::string::npos);
  AnimatorProfile bad = WithSkill(1.5);
  EXPECT_NE(ErrorOf([&] { PerformTake(story, 0, bad, 0, options, 1); }).find("animator.skill"),
            std::string::npos);
}

}  // namespace
}  // namespace mmh::people
