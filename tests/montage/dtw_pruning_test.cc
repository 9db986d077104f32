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

// Similar takes of a story: the reference has `frames`, the others +-10 %.
synthetic::TakeSet Story(int takes, int frames, std::uint64_t seed) {
  synthetic::TakeSetOptions options;
  options.takes = takes;
  options.reference_frames = frames;
  options.min_frames = frames * 9 / 10;
  options.max_frames = frames * 11 / 10;
  options.seed = seed;
  return synthetic::MakeTakeSet(options);
}

TEST(DtwPruning, ExactFarFromTheOrigin) {
  const auto set = Story(3, 600, 3);
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
  const auto set = Story(2, 1500, 11);
  const DtwResult a = ComputeDtw(set.takes[0], set.takes[1], DtwOptions{});
  // All passes together evaluate well under a third of the cells on similar takes.
  EXPECT_LT(a.summary.cells_evaluated, a.summary.cells_total / 3) << a.summary.cells_evaluated;
}

}  // namespace
}  // namespace mmh::montage
