// The DTW on translations that overflow its costs: every step pattern, pruned or not, refuses
// them with an InputError naming the take and frame (it crashed: an empty warp read, a heap write
// before a buffer in the symmetric walk back), and the largest accepted coordinates (1e6 m) give a
// valid warp with a finite cost.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "core/resource_limits.h"
#include "montage/dtw.h"
#include "tests/montage/oracles.h"
#include "tools/synthetic_takes.h"

namespace mmh::montage {
namespace {

using ::testing::HasSubstr;

std::vector<Trajectory> Takes(double scale) {
  synthetic::TakeSetOptions options;
  options.takes = 2;
  options.reference_frames = 120;
  options.min_frames = 110;
  options.max_frames = 130;
  options.seed = 5;
  std::vector<Trajectory> takes = synthetic::MakeTakeSet(options).takes;
  for (auto& take : takes) {
    for (auto& pose : take.poses) pose.translation *= scale;
  }
  return takes;
}

std::vector<DtwOptions> AllPatterns() {
  std::vector<DtwOptions> all;
  for (StepPattern pattern :
       {StepPattern::kLiteral, StepPattern::kSlopeLimited, StepPattern::kSymmetric}) {
    for (bool prune : {true, false}) {
      DtwOptions o;
      o.step_pattern = pattern;
      o.prune = prune;
      all.push_back(o);
    }
  }
  return all;
}

TEST(DtwRobustness, HugeTranslationsAreRefusedForEveryStepPattern) {
  for (double value : {1e150, 1e200, 1e300}) {
    std::vector<Trajectory> takes = Takes(1.0);
    for (auto& take : takes) {
      for (auto& pose : take.poses) pose.translation.setConstant(value);
    }
    for (const DtwOptions& options : AllPatterns()) {
      SCOPED_TRACE(std::to_string(static_cast<int>(options.step_pattern)) + " prune " +
                   std::to_string(options.prune) + " value " + std::to_string(value));
      try {
        ComputeDtw(takes[0], takes[1], options);
        ADD_FAILURE() << "accepted";
      } catch (const InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("DTW reference take, frame 0: got translation"));
        EXPECT_THAT(e.what(), HasSubstr("within +-1e6 m"));
      }
    }
  }
}

TEST(DtwRobustness, LargestAcceptedCoordinatesGiveAValidWarp) {
  // Takes spread over +-1e6 m: costs up to ~1e7 per frame, sums far from overflowing.
  std::vector<Trajectory> takes = Takes(1.0);
  for (auto& take : takes) {
    for (std::size_t i = 0; i < take.size(); ++i) {
      take.poses[i].translation.x() = (i % 2 ? 1 : -1) * kMaxTranslationMetres;
    }
  }
  for (const DtwOptions& options : AllPatterns()) {
    const DtwResult result = ComputeDtw(takes[0], takes[1], options);
    EXPECT_TRUE(std::isfinite(result.summary.cost));
    EXPECT_TRUE(IsValidWarp(result.warp, static_cast<int>(takes[1].size()), options.step_pattern));
  }
}

TEST(DtwRobustness, NonFiniteQuaternionsAreRefused) {
  std::vector<Trajectory> takes = Takes(1.0);
  takes[1].poses[7].rotation.coeffs()[0] = std::nan("");
  for (const DtwOptions& options : AllPatterns()) {
    try {
      ComputeDtw(takes[0], takes[1], options);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr("DTW source take, frame 7"));
    }
  }
}

}  // namespace
}  // namespace mmh::montage
