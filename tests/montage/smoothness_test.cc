// Oracle: the smoothness table of eq. 9 against a direct evaluation of the formula.
#include "montage/smoothness.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "tests/montage/oracles.h"

namespace mmh::montage {
namespace {

using oracle::NearRel;

struct TakeSet {
  std::vector<Trajectory> takes;
  std::vector<std::vector<int>> warps;
  int n = 0;
};

TakeSet RandomSetup(std::mt19937_64& rng, int n, int m, int min_len, int max_len, bool similar) {
  TakeSet s;
  s.n = n;
  const oracle::RandomWalkPath path(rng, 200);
  for (int l = 0; l < m; ++l) {
    const int N = l == 0 ? n : std::uniform_int_distribution<int>(min_len, max_len)(rng);
    Trajectory take =
        similar ? oracle::SampleTake(path, N, 0.3 * (l % 3) - 0.3, 0.7 * l, 0.003, 0.01, rng)
                : oracle::RandomTrajectory(rng, N);
    s.takes.push_back(oracle::FlipSigns(take, rng, 0.3));
    if (l == 0) {
      std::vector<int> id(n);
      std::iota(id.begin(), id.end(), 0);
      s.warps.push_back(id);
    } else {
      s.warps.push_back(oracle::RandomMonotoneWarp(rng, n, N));
    }
  }
  return s;
}

// Eq. 9 has no valid pair when w_l(t) + h and w_k(t+1) + h - 1 are never both inside; the scaled
// mean is then undefined and such entries are not compared.
int ValidPairs(const TakeSet& s, int t, int l, int k, int half_window) {
  int valid = 0;
  for (int h = -half_window; h <= half_window; ++h) {
    const int i = s.warps[l][t] + h, j = s.warps[k][t + 1] + h - 1;
    valid += i >= 0 && i < int(s.takes[l].size()) && j >= 0 && j < int(s.takes[k].size());
  }
  return valid;
}

void CheckTable(const TakeSet& s, const SmoothnessOptions& options, const std::string& where) {
  SCOPED_TRACE(where);
  const int m = int(s.takes.size());
  const TransitionCosts table = ComputeSmoothnessCosts(s.takes, s.warps, options);
  ASSERT_EQ(table.frames, s.n);
  ASSERT_EQ(table.takes, m);
  ASSERT_EQ(table.values.size(), std::size_t(std::max(0, s.n - 1)) * m * m);
  const bool scaled = options.window_edge == WindowEdge::kScaledMean;
  int truncated_entries = 0;
  for (int t = 0; t + 1 < s.n; ++t) {
    for (int l = 0; l < m; ++l) {
      for (int k = 0; k < m; ++k) {
        const double got = table.at(t, l, k);
        // Storage layout promised by the header.
        EXPECT_EQ(got, table.values[(std::size_t(t) * m + l) * m + k]);
        if (l == k) {
          EXPECT_EQ(got, 0.0) << "diagonal t=" << t << " l=" << l;
          continue;
        }
        const int valid = ValidPairs(s, t, l, k, options.half_window);
        if (valid < 2 * options.half_window + 1) ++truncated_entries;
        if (valid == 0 && scaled) continue;
        const double want = oracle::MySmoothness(s.takes[l], s.warps[l], s.takes[k], s.warps[k], t,
                                                 options.lambda, options.half_window, scaled);
        EXPECT_TRUE(NearRel(got, want, 1e-12))
            << "t=" << t << " l=" << l << " k=" << k << " valid=" << valid << ": table " << got
            << ", eq. 9 " << want;
        const double direct =
            SmoothnessCost(s.takes[l], s.warps[l], s.takes[k], s.warps[k], t, options);
        EXPECT_TRUE(NearRel(direct, want, 1e-12)) << "SmoothnessCost t=" << t << " l=" << l
                                                  << " k=" << k << ": " << direct << " vs " << want;
        if (::testing::Test::HasFailure()) return;
      }
    }
  }
  EXPECT_GT(truncated_entries, 0);  // the window edges were exercised
}

TEST(Smoothness, TableMatchesEq9TruncatedSum) {
  std::mt19937_64 rng(909);
  for (int rep = 0; rep < 12; ++rep) {
    const int n = std::uniform_int_distribution<int>(20, 150)(rng);
    const int m = std::uniform_int_distribution<int>(2, 4)(rng);
    const TakeSet s = RandomSetup(rng, n, m, 16, 200, rep % 2 == 0);
    SmoothnessOptions o;
    o.window_edge = WindowEdge::kTruncatedSum;
    CheckTable(s, o, "rep " + std::to_string(rep));
    if (HasFailure()) return;
  }
}

TEST(Smoothness, TableMatchesEq9ScaledMean) {
  std::mt19937_64 rng(910);
  for (int rep = 0; rep < 12; ++rep) {
    const int n = std::uniform_int_distribution<int>(20, 150)(rng);
    const int m = std::uniform_int_distribution<int>(2, 4)(rng);
    const TakeSet s = RandomSetup(rng, n, m, 16, 200, rep % 2 == 1);
    SmoothnessOptions o;  // the defaults: lambda 0.8, W = [-7, 7], scaled mean
    EXPECT_EQ(o.lambda, 0.8);
    EXPECT_EQ(o.half_window, 7);
    EXPECT_EQ(o.window_edge, WindowEdge::kScaledMean);
    CheckTable(s, o, "rep " + std::to_string(rep));
    if (HasFailure()) return;
  }
}

TEST(Smoothness, OtherWindowsAndLambdas) {
  std::mt19937_64 rng(911);
  for (int rep = 0; rep < 8; ++rep) {
    const int n = std::uniform_int_distribution<int>(15, 80)(rng);
    const TakeSet s = RandomSetup(rng, n, 3, 10, 100, true);
    SmoothnessOptions o;
    o.half_window = 1 + int(rng() % 10);
    o.lambda = std::uniform_real_distribution<double>(0.0, 4.0)(rng);
    o.window_edge = rep % 2 ? WindowEdge::kScaledMean : WindowEdge::kTruncatedSum;
    CheckTable(s, o,
               "rep " + std::to_string(rep) + " half_window " + std::to_string(o.half_window));
    if (HasFailure()) return;
  }
}

// Hand-worked: two constant takes. T_0 is identity at the origin (3 frames), T_1 the identity
// rotation at (1, 0, 0) (3 frames), identity warps, t = 0, lambda 0.8, W = [-7, 7].
// Pairs (w_0(0) + h, w_1(1) + h - 1) = (h, h) for h in [0, 2]: 3 valid pairs of cost 0.8 each.
// Truncated sum 2.4; scaled mean 2.4 * 15 / 3 = 12.
TEST(Smoothness, HandWorked) {
  Trajectory a = oracle::MakeTrajectory(std::vector<Rigid3>(3, Rigid3()));
  Rigid3 shifted;
  shifted.translation = Eigen::Vector3d(1, 0, 0);
  Trajectory b = oracle::MakeTrajectory(std::vector<Rigid3>(3, shifted));
  const std::vector<int> id = {0, 1, 2};
  SmoothnessOptions o;
  o.window_edge = WindowEdge::kTruncatedSum;
  EXPECT_NEAR(SmoothnessCost(a, id, b, id, 0, o), 2.4, 1e-12);
  const TransitionCosts tt = ComputeSmoothnessCosts({a, b}, {id, id}, o);
  EXPECT_NEAR(tt.at(0, 0, 1), 2.4, 1e-12);
  EXPECT_NEAR(tt.at(0, 1, 0), 2.4, 1e-12);
  EXPECT_EQ(tt.at(0, 0, 0), 0.0);
  o.window_edge = WindowEdge::kScaledMean;
  EXPECT_NEAR(SmoothnessCost(a, id, b, id, 0, o), 12.0, 1e-12);
  EXPECT_NEAR(ComputeSmoothnessCosts({a, b}, {id, id}, o).at(1, 1, 0), 12.0, 1e-12);
}

}  // namespace
}  // namespace mmh::montage
