// Oracle: enumerate every admissible warp / path of tiny DTW problems (eqs. 1-5), textbook full
// dynamic programmes on larger ones, and pruning against the full programme.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "montage/dtw.h"
#include "montage/match_cost.h"
#include "tests/montage/oracles.h"

namespace mmh::montage {
namespace {

using oracle::NearRel;

std::string WarpString(const std::vector<int>& w) {
  std::ostringstream os;
  for (std::size_t i = 0; i < w.size(); ++i) os << (i ? "," : "") << w[i];
  return os.str();
}

// Every w: [0,n) -> [0,N), non-decreasing, w(0) = 0, w(n-1) = N-1, steps <= max_step (< 0: any).
void EnumerateWarps(int n, int N, int max_step,
                    const std::function<void(const std::vector<int>&)>& f) {
  std::vector<int> w(n);
  std::function<void(int)> rec = [&](int t) {
    if (t == n) {
      if (w[n - 1] == N - 1) f(w);
      return;
    }
    const int lo = w[t - 1];
    const int hi = max_step < 0 ? N - 1 : std::min(N - 1, w[t - 1] + max_step);
    for (int j = lo; j <= hi; ++j) {
      w[t] = j;
      rec(t + 1);
    }
  };
  w[0] = 0;
  if (n == 1) {
    if (N == 1) f(w);
    return;
  }
  rec(1);
}

struct PathInfo {
  double cost;
  std::vector<int> warp;  // first source frame of each reference frame on the path
};

// Every path (0,0) -> (n-1,N-1) with steps (1,0), (0,1), (1,1) (reference, source).
std::vector<PathInfo> EnumerateSymmetricPaths(const Trajectory& ref, const Trajectory& src,
                                              double lambda) {
  const int n = int(ref.size()), N = int(src.size());
  std::vector<PathInfo> out;
  std::vector<int> first(n, -1);
  std::function<void(int, int, double)> rec = [&](int t, int j, double cost) {
    const int saved = first[t];
    if (first[t] < 0) first[t] = j;
    cost += oracle::Cmatch(ref.poses[t], src.poses[j], lambda);
    if (t == n - 1 && j == N - 1) {
      out.push_back({cost, first});
    } else {
      if (t + 1 < n) rec(t + 1, j, cost);
      if (j + 1 < N) rec(t, j + 1, cost);
      if (t + 1 < n && j + 1 < N) rec(t + 1, j + 1, cost);
    }
    first[t] = saved;
  };
  rec(0, 0, 0.0);
  return out;
}

Trajectory TinyTrajectory(std::mt19937_64& rng, int frames, const Trajectory* copy_from) {
  Trajectory t = oracle::RandomTrajectory(rng, frames);
  // Sometimes reuse poses of the other take (exact ties and zero costs).
  if (copy_from != nullptr && rng() % 4 == 0) {
    for (int i = 0; i < frames; ++i) {
      if (rng() % 2) t.poses[i] = copy_from->poses[rng() % copy_from->size()];
    }
  }
  return oracle::FlipSigns(t, rng);
}

TEST(DtwExhaustive, MatchCostIsEq5WithSignRule) {
  std::mt19937_64 rng(5);
  for (int rep = 0; rep < 1000; ++rep) {
    const Trajectory a = oracle::RandomTrajectory(rng, 1), b = oracle::RandomTrajectory(rng, 1);
    const double lambda = std::uniform_real_distribution<double>(0.0, 5.0)(rng);
    const double mine = oracle::Cmatch(a.poses[0], b.poses[0], lambda);
    EXPECT_TRUE(NearRel(MatchCost(a.poses[0], b.poses[0], lambda), mine, 1e-13));
    Rigid3 flipped = b.poses[0];
    flipped.rotation = oracle::Negated(flipped.rotation);
    EXPECT_EQ(MatchCost(a.poses[0], b.poses[0], lambda), MatchCost(a.poses[0], flipped, lambda));
  }
  Rigid3 same;
  EXPECT_EQ(MatchCost(same, same, 2.5), 0.0);
}

TEST(DtwExhaustive, TinyProblemsAllPatterns) {
  std::mt19937_64 rng(1234567);
  int compared[3] = {0, 0, 0};
  int invalid_symmetric = 0, symmetric_end_not_pinned = 0;
  std::string invalid_example, end_example;
  for (int rep = 0; rep < 2500; ++rep) {
    const int n = std::uniform_int_distribution<int>(1, 6)(rng);
    const int N = std::uniform_int_distribution<int>(1, 6)(rng);
    const Trajectory ref = TinyTrajectory(rng, n, nullptr);
    const Trajectory src = TinyTrajectory(rng, N, &ref);
    DtwOptions options;
    if (rng() % 3 == 0) options.lambda = std::uniform_real_distribution<double>(0.0, 6.0)(rng);
    const std::string where = "rep " + std::to_string(rep) + " n=" + std::to_string(n) +
                              " N=" + std::to_string(N) +
                              " lambda=" + std::to_string(options.lambda);
    SCOPED_TRACE(where);

    // kLiteral and kSlopeLimited: enumerate warps.
    for (StepPattern pattern : {StepPattern::kLiteral, StepPattern::kSlopeLimited}) {
      const int max_step = pattern == StepPattern::kLiteral ? -1 : 2;
      const bool exists = (n == 1) ? N == 1 : (max_step < 0 || N - 1 <= 2 * (n - 1));
      DtwOptions o = options;
      o.step_pattern = pattern;
      if (!exists) {
        EXPECT_THROW(ComputeDtw(ref, src, o), mmh::InputError)
            << "pattern " << int(pattern) << ": no warp exists";
        continue;
      }
      double best = oracle::kInf;
      int count = 0;
      EnumerateWarps(n, N, max_step, [&](const std::vector<int>& w) {
        ++count;
        EXPECT_TRUE(IsValidWarp(w, N, pattern)) << "enumerated warp " << WarpString(w);
        best = std::min(best, oracle::MyWarpCost(ref, src, w, o.lambda));
      });
      ASSERT_GT(count, 0);
      for (bool prune : {true, false}) {
        o.prune = prune;
        const DtwResult r = ComputeDtw(ref, src, o);
        ++compared[int(pattern)];
        EXPECT_TRUE(IsValidWarp(r.warp, N, pattern)) << "returned warp " << WarpString(r.warp);
        ASSERT_EQ(int(r.warp.size()), n);
        EXPECT_EQ(r.warp.front(), 0);
        EXPECT_EQ(r.warp.back(), N - 1);
        for (int t = 1; t < n; ++t) {
          EXPECT_GE(r.warp[t], r.warp[t - 1]);
          if (max_step > 0) {
            EXPECT_LE(r.warp[t] - r.warp[t - 1], max_step);
          }
        }
        EXPECT_TRUE(NearRel(r.summary.cost, best))
            << "pattern " << int(pattern) << " prune " << prune << ": exhaustive optimum " << best
            << ", got " << r.summary.cost << " warp " << WarpString(r.warp);
        EXPECT_TRUE(NearRel(WarpCost(ref, src, r.warp, o.lambda), r.summary.cost))
            << "WarpCost(result.warp) " << WarpCost(ref, src, r.warp, o.lambda)
            << " != summary.cost " << r.summary.cost;
        EXPECT_TRUE(NearRel(oracle::MyWarpCost(ref, src, r.warp, o.lambda), best));
        EXPECT_EQ(r.summary.cells_total, std::int64_t(n) * N);
        EXPECT_LE(r.summary.cells_evaluated, r.summary.cells_total);
      }
    }

    // kSymmetric: enumerate paths. (n = 1 < N: the header lists it as infeasible for every
    // pattern, but a symmetric path exists; not asserted either way.)
    if (!(n == 1 && N > 1)) {
      DtwOptions o = options;
      o.step_pattern = StepPattern::kSymmetric;
      const std::vector<PathInfo> paths = EnumerateSymmetricPaths(ref, src, o.lambda);
      double best = oracle::kInf;
      for (const auto& p : paths) best = std::min(best, p.cost);
      const DtwResult r = ComputeDtw(ref, src, o);
      ++compared[2];
      ASSERT_EQ(int(r.warp.size()), n);
      // Counted, not failed here, so that the other checks keep running on every instance.
      if (!IsValidWarp(r.warp, N, StepPattern::kSymmetric)) {
        if (invalid_symmetric++ == 0) {
          invalid_example = where + ": ComputeDtw(kSymmetric) warp " + WarpString(r.warp) +
                            " rejected by IsValidWarp(.., N=" + std::to_string(N) + ", kSymmetric)";
        }
      }
      if (r.warp.back() != N - 1) {
        if (symmetric_end_not_pinned++ == 0) {
          end_example = where + ": warp " + WarpString(r.warp) + " ends at " +
                        std::to_string(r.warp.back()) + ", expected N-1 = " + std::to_string(N - 1);
        }
      }
      EXPECT_TRUE(NearRel(r.summary.cost, best))
          << "symmetric exhaustive optimum " << best << ", got " << r.summary.cost;
      // The warp must be that of an optimal path: w(t) = first source frame on the path for t,
      // except that the last entry may be pinned to N-1 (the header's w(n-1) = N-1).
      bool found = false;
      for (const auto& p : paths) {
        if (!NearRel(p.cost, best)) continue;
        bool same = true;
        for (int t = 0; t + 1 < n; ++t) same = same && p.warp[t] == r.warp[t];
        same = same && (r.warp[n - 1] == p.warp[n - 1] || r.warp[n - 1] == N - 1);
        if (same) found = true;
      }
      EXPECT_TRUE(found) << "warp " << WarpString(r.warp) << " is not that of an optimal path";
    }
    if (HasFailure()) break;
  }
  // DtwResult promises w(n-1) = N-1 for every pattern, and IsValidWarp must accept the warps
  // that ComputeDtw returns.
  EXPECT_EQ(symmetric_end_not_pinned, 0) << "first: " << end_example;
  EXPECT_EQ(invalid_symmetric, 0) << "first: " << invalid_example;
  EXPECT_GT(compared[0], 2000);
  EXPECT_GT(compared[1], 1500);
  EXPECT_GT(compared[2], 1500);
}

TEST(DtwExhaustive, IsValidWarpMatchesDefinition) {
  std::mt19937_64 rng(77);
  for (int rep = 0; rep < 5000; ++rep) {
    const int n = std::uniform_int_distribution<int>(1, 8)(rng);
    const int N = std::uniform_int_distribution<int>(1, 8)(rng);
    std::vector<int> w(n);
    // Mostly near-valid warps with random corruption.
    w[0] = (rng() % 8 == 0) ? 1 : 0;
    for (int t = 1; t < n; ++t) {
      const int step = int(rng() % 4) - (rng() % 10 == 0 ? 1 : 0);
      w[t] = w[t - 1] + step;
    }
    if (rng() % 2) w[n - 1] = N - 1;
    bool in_range = true, monotone = true, max2 = true;
    for (int t = 0; t < n; ++t) in_range = in_range && w[t] >= 0 && w[t] < N;
    for (int t = 1; t < n; ++t) {
      monotone = monotone && w[t] >= w[t - 1];
      max2 = max2 && w[t] - w[t - 1] <= 2;
    }
    const bool ends = w[0] == 0 && w[n - 1] == N - 1;
    const bool literal = in_range && monotone && ends;
    EXPECT_EQ(IsValidWarp(w, N, StepPattern::kLiteral), literal)
        << "N=" << N << " w=" << WarpString(w);
    EXPECT_EQ(IsValidWarp(w, N, StepPattern::kSlopeLimited), literal && max2)
        << "N=" << N << " w=" << WarpString(w);
    if (HasFailure()) break;
  }
}

// Medium sizes: textbook full dynamic programmes for all three patterns.
TEST(DtwExhaustive, MediumSizesMatchTextbookDp) {
  std::mt19937_64 rng(2024);
  for (int rep = 0; rep < 16; ++rep) {
    const int n = std::uniform_int_distribution<int>(30, 200)(rng);
    const int N = std::uniform_int_distribution<int>(n / 2 + 1, std::min(2 * n - 1, 250))(rng);
    Trajectory ref, src;
    if (rep % 2 == 0) {
      const oracle::RandomWalkPath path(rng, 300);
      ref = oracle::SampleTake(path, n, 0.3, 0.5, 0.003, 0.01, rng);
      src = oracle::FlipSigns(oracle::SampleTake(path, N, -0.4, 1.5, 0.003, 0.01, rng), rng);
    } else {
      ref = oracle::RandomTrajectory(rng, n);
      src = oracle::RandomTrajectory(rng, N);
    }
    SCOPED_TRACE("rep " + std::to_string(rep) + " n=" + std::to_string(n) +
                 " N=" + std::to_string(N));
    DtwOptions o;
    o.step_pattern = StepPattern::kLiteral;
    DtwResult r = ComputeDtw(ref, src, o);
    EXPECT_TRUE(NearRel(r.summary.cost, oracle::DtwWarpDp(ref, src, o.lambda, -1)));
    EXPECT_TRUE(IsValidWarp(r.warp, N, o.step_pattern));
    o.step_pattern = StepPattern::kSlopeLimited;
    r = ComputeDtw(ref, src, o);
    EXPECT_TRUE(NearRel(r.summary.cost, oracle::DtwWarpDp(ref, src, o.lambda, 2)));
    EXPECT_TRUE(IsValidWarp(r.warp, N, o.step_pattern));
    EXPECT_TRUE(NearRel(WarpCost(ref, src, r.warp, o.lambda), r.summary.cost));
    o.step_pattern = StepPattern::kSymmetric;
    r = ComputeDtw(ref, src, o);
    EXPECT_TRUE(NearRel(r.summary.cost, oracle::DtwSymmetricDp(ref, src, o.lambda)))
        << "symmetric DP " << oracle::DtwSymmetricDp(ref, src, o.lambda) << " vs "
        << r.summary.cost;
    EXPECT_TRUE(IsValidWarp(r.warp, N, o.step_pattern))
        << "symmetric warp ends at " << r.warp.back() << ", N-1 = " << N - 1;
  }
}

// Pruning must not change anything: same warp, same cost, bit for bit.
TEST(DtwExhaustive, PruneIsExact) {
  std::mt19937_64 rng(8080);
  for (int rep = 0; rep < 12; ++rep) {
    const int n = std::uniform_int_distribution<int>(200, 700)(rng);
    const int N = std::uniform_int_distribution<int>(200, 700)(rng);
    Trajectory ref, src;
    const bool similar = rep < 8;
    if (similar) {
      const oracle::RandomWalkPath path(rng, 400);
      std::uniform_real_distribution<double> amp(-0.6, 0.6), phase(0.0, 6.28);
      const double noise = rep % 2 ? 0.002 : 0.01;
      ref = oracle::SampleTake(path, n, amp(rng), phase(rng), noise, 3 * noise, rng);
      src = oracle::SampleTake(path, N, amp(rng), phase(rng), noise, 3 * noise, rng);
      if (rep % 4 == 3) src = oracle::FlipSigns(src, rng);
    } else {
      ref = oracle::RandomTrajectory(rng, n);
      src = oracle::RandomTrajectory(rng, N);
    }
    SCOPED_TRACE("rep " + std::to_string(rep) + (similar ? " similar" : " random") +
                 " n=" + std::to_string(n) + " N=" + std::to_string(N));
    DtwOptions pruned, full;
    pruned.prune = true;
    full.prune = false;
    const DtwResult a = ComputeDtw(ref, src, pruned);
    const DtwResult b = ComputeDtw(ref, src, full);
    EXPECT_EQ(a.warp, b.warp);
    EXPECT_EQ(a.summary.cost, b.summary.cost);  // bit-identical
    EXPECT_TRUE(NearRel(b.summary.cost, oracle::DtwWarpDp(ref, src, full.lambda, -1)))
        << "full DP " << oracle::DtwWarpDp(ref, src, full.lambda, -1) << " vs " << b.summary.cost;
    EXPECT_TRUE(IsValidWarp(a.warp, N, StepPattern::kLiteral));
    EXPECT_TRUE(NearRel(WarpCost(ref, src, a.warp, pruned.lambda), a.summary.cost));
    EXPECT_EQ(a.summary.cells_total, std::int64_t(n) * N);
    EXPECT_GT(a.summary.cells_evaluated, 0);
    EXPECT_LE(b.summary.cells_evaluated, b.summary.cells_total);
    // The pruned programme's count includes its coarse and band passes: on similar takes it must
    // still evaluate fewer cells than the full programme; on unrelated ones at most ~3 passes.
    if (similar) {
      EXPECT_LT(a.summary.cells_evaluated, b.summary.cells_evaluated);
    } else {
      EXPECT_LE(a.summary.cells_evaluated, 3 * a.summary.cells_total);
    }
  }
}

TEST(DtwExhaustive, QuaternionSignDoesNotMatter) {
  std::mt19937_64 rng(999);
  for (int rep = 0; rep < 6; ++rep) {
    const int n = std::uniform_int_distribution<int>(100, 400)(rng);
    const int N = std::uniform_int_distribution<int>(n / 2 + 1, std::min(2 * n - 1, 500))(rng);
    const oracle::RandomWalkPath path(rng, 300);
    const Trajectory ref = oracle::SampleTake(path, n, 0.2, 0.3, 0.004, 0.01, rng);
    const Trajectory src = oracle::SampleTake(path, N, -0.3, 2.0, 0.004, 0.01, rng);
    const Trajectory src_flipped = oracle::FlipSigns(src, rng);
    const Trajectory ref_flipped = oracle::FlipSigns(ref, rng);
    for (StepPattern pattern :
         {StepPattern::kLiteral, StepPattern::kSlopeLimited, StepPattern::kSymmetric}) {
      DtwOptions o;
      o.step_pattern = pattern;
      const DtwResult a = ComputeDtw(ref, src, o);
      const DtwResult b = ComputeDtw(ref, src_flipped, o);
      const DtwResult c = ComputeDtw(ref_flipped, src_flipped, o);
      EXPECT_EQ(a.warp, b.warp) << "pattern " << int(pattern);
      EXPECT_EQ(a.warp, c.warp) << "pattern " << int(pattern);
      EXPECT_EQ(a.summary.cost, b.summary.cost) << "pattern " << int(pattern);
      EXPECT_EQ(a.summary.cost, c.summary.cost) << "pattern " << int(pattern);
    }
  }
}

TEST(DtwExhaustive, InfeasibleAndEmptyInputsThrow) {
  std::mt19937_64 rng(3);
  const Trajectory one = oracle::RandomTrajectory(rng, 1);
  const Trajectory two = oracle::RandomTrajectory(rng, 2);
  const Trajectory three = oracle::RandomTrajectory(rng, 3);
  const Trajectory five = oracle::RandomTrajectory(rng, 5);
  const Trajectory six = oracle::RandomTrajectory(rng, 6);
  const Trajectory empty;
  DtwOptions literal, slope;
  slope.step_pattern = StepPattern::kSlopeLimited;
  EXPECT_THROW(ComputeDtw(one, two, literal), mmh::InputError);
  EXPECT_THROW(ComputeDtw(one, two, slope), mmh::InputError);
  {
    // The header lists n = 1 < N as infeasible for every pattern (w(0) = 0 and w(n-1) = N-1
    // cannot both hold).
    DtwOptions symmetric;
    symmetric.step_pattern = StepPattern::kSymmetric;
    EXPECT_THROW(ComputeDtw(one, two, symmetric), mmh::InputError);
  }
  EXPECT_THROW(ComputeDtw(three, six, slope), mmh::InputError);  // 5 > 2 * 2
  EXPECT_NO_THROW(ComputeDtw(three, five, slope));               // 4 <= 2 * 2
  EXPECT_NO_THROW(ComputeDtw(three, six, literal));
  EXPECT_NO_THROW(ComputeDtw(six, one, literal));  // N = 1: the warp is all zeros
  EXPECT_EQ(ComputeDtw(six, one, literal).warp, std::vector<int>(6, 0));
  EXPECT_NO_THROW(ComputeDtw(one, one, literal));
  for (StepPattern pattern :
       {StepPattern::kLiteral, StepPattern::kSlopeLimited, StepPattern::kSymmetric}) {
    DtwOptions o;
    o.step_pattern = pattern;
    EXPECT_THROW(ComputeDtw(empty, three, o), mmh::InputError);
    EXPECT_THROW(ComputeDtw(three, empty, o), mmh::InputError);
  }
}

}  // namespace
}  // namespace mmh::montage
