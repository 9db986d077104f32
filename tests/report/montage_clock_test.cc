// The 3D view's clocks (report/montage_clock.h) against the paper's unwarping played frame by
// frame: every reference run of take l plays w_l(t - 1) + 1 .. w_l(t) at each t (its first t
// from w_l(t)).
#include "report/montage_clock.h"

#include <gtest/gtest.h>

#include <random>

#include "core/error.h"
#include "montage/blend.h"

namespace mmh::report {
namespace {

TEST(MontageClock, ByHand) {
  // Take 0 is the reference; take 1 runs at double speed, then holds (montage/blend_test.cc).
  const std::vector<std::vector<int>> warps = {{0, 1, 2, 3, 4, 5}, {0, 2, 4, 6, 6, 6}};
  const MontageClock clock = ComputeMontageClock(montage::Unwarp({0, 1, 1, 0, 1, 1}, warps), warps);
  // Montage frames: take 0 frame 0 (t 0); take 1 frames 2, 3, 4 (t 1, 2, 2); take 0 frame 3
  // (t 3); take 1 frame 6 once (t 4).
  EXPECT_EQ(clock.reference, (std::vector<int>{0, 1, 2, 2, 3, 4}));
  EXPECT_EQ(clock.takes[0], (std::vector<int>{0, 1, 2, 2, 3, 4}));
  EXPECT_EQ(clock.takes[1], (std::vector<int>{0, 2, 3, 4, 6, 6}));
}

TEST(MontageClock, EqualsTheUnwarpedMontagePlayedFrameByFrame) {
  std::mt19937_64 rng(22);
  for (int rep = 0; rep < 200; ++rep) {
    SCOPED_TRACE("rep " + std::to_string(rep));
    const int n = std::uniform_int_distribution<int>(1, 60)(rng);
    const int takes = std::uniform_int_distribution<int>(1, 4)(rng);
    std::vector<std::vector<int>> warps(takes);
    for (auto& warp : warps) {
      int w = std::uniform_int_distribution<int>(0, 3)(rng);
      for (int t = 0; t < n; ++t) {
        warp.push_back(w);
        w += std::uniform_int_distribution<int>(0, 3)(rng);  // holds and skips
      }
    }
    std::vector<int> labels(n);
    for (int t = 0, l = 0; t < n; ++t) {
      if (std::uniform_int_distribution<int>(0, 5)(rng) == 0) l = std::uniform_int_distribution<int>(0, takes - 1)(rng);
      labels[t] = l;
    }
    std::vector<int> reference, source, take;
    for (int t = 0; t < n; ++t) {
      const int l = labels[t];
      const int from = t > 0 && labels[t - 1] == l ? warps[l][t - 1] + 1 : warps[l][t];
      for (int j = from; j <= warps[l][t]; ++j) {
        reference.push_back(t);
        source.push_back(j);
        take.push_back(l);
      }
    }
    const MontageClock clock = ComputeMontageClock(montage::Unwarp(labels, warps), warps);
    ASSERT_EQ(clock.reference, reference);
    for (int k = 0; k < takes; ++k) {
      for (std::size_t f = 0; f < reference.size(); ++f) {
        ASSERT_EQ(clock.takes[k][f], take[f] == k ? source[f] : warps[k][reference[f]])
            << "take " << k << " montage frame " << f;
      }
    }
  }
}

TEST(MontageClock, SegmentsThatDoNotTileAreInputErrors) {
  const std::vector<std::vector<int>> warps = {{0, 1, 2}};
  EXPECT_THROW(ComputeMontageClock({{0, 0, 2, 0, 2, 1, 3}}, warps), InputError);  // starts at 1
  EXPECT_THROW(ComputeMontageClock({{1, 0, 2, 0, 2, 0, 2}}, warps), InputError);  // no take 1
  EXPECT_THROW(ComputeMontageClock({{0, 0, 5, 0, 2, 0, 2}}, warps), InputError);  // past the end
}

}  // namespace
}  // namespace mmh::report
