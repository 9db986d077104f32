// The pruned DTW's single-precision lower bounds carry a rounding margin that grows with the
// coordinates' magnitude: far from the origin (a world frame 1 km or 100 km away) the pruned
// programme must still return the full programme's warp, bit for bit.
#include <gtest/gtest.h>

#include <cmath>

#include "montage/dtw.h"
#include "tests/montage/oracles.h"
#include "tools/synthetic_takes.h"

namespace mmh::montage {
namespace {

TEST(DtwPruning, ExactFarFromTheOrigin) {
  synthetic::TakeSetOptions options;
  options.takes = 3;
  options.reference_frames = 600;
  options.min_frames = 540;
  options.max_frames = 660;
  options.seed = 3;
  const auto set = synthetic::MakeTakeSet(options);
  for (double offset : {0.0, 1e3, 1e5}) {
    SCOPED_TRACE("offset " + std::to_string(offset));
    std::vector<Trajectory> takes = set.takes;
    for (auto& take : takes) {
      for (auto& pose : take.poses) pose.translation += Eigen::Vector3d(offset, -offset, offset);
    }
    for (int k = 1; k < 3; ++k) {
      DtwOptions pruned, full;
      full.prune = false;
      const DtwResult a = ComputeDtw(takes[0], takes[k], pruned);
      const DtwResult b = ComputeDtw(takes[0], takes[k], full);
      EXPECT_EQ(a.warp, b.warp);
      EXPECT_EQ(a.summary.cost, b.summary.cost);
      EXPECT_TRUE(IsValidWarp(a.warp, static_cast<int>(takes[k].size()), StepPattern::kLiteral));
    }
  }
}

TEST(DtwPruning, PrunesOnSimilarTakes) {
  synthetic::TakeSetOptions options;
  options.takes = 2;
  options.reference_frames = 1500;
  options.min_frames = 1350;
  options.max_frames = 1650;
  options.seed = 11;
  const auto set = synthetic::MakeTakeSet(options);
  const DtwResult a = ComputeDtw(set.takes[0], set.takes[1], DtwOptions{});
  // All passes together evaluate well under a third of the cells on similar takes.
  EXPECT_LT(a.summary.cells_evaluated, a.summary.cells_total / 3) << a.summary.cells_evaluated;
}

}  // namespace
}  // namespace mmh::montage
