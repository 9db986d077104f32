// Oracle tests of the reaction shift and the annotation warp of eq. 6.
#include "montage/annotation_warp.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include "tests/montage/oracles.h"

namespace mmh::montage {
namespace {

TEST(AnnotationWarp, ReactionShiftFrames) {
  EXPECT_EQ(ReactionShiftFrames(0.3, 1.0 / 30.0), 9);
  EXPECT_EQ(ReactionShiftFrames(0.0, 1.0 / 30.0), 0);
  EXPECT_EQ(ReactionShiftFrames(0.3, 1.0 / 60.0), 18);
  EXPECT_EQ(ReactionShiftFrames(0.3, 0.1), 3);
}

TEST(AnnotationWarp, ShiftForReactionByHand) {
  const std::vector<double> v = {1, 2, 3, 4, 5};
  EXPECT_EQ(ShiftForReaction(v, 0), v);
  EXPECT_EQ(ShiftForReaction(v, 1), (std::vector<double>{2, 3, 4, 5, 5}));
  EXPECT_EQ(ShiftForReaction(v, 2), (std::vector<double>{3, 4, 5, 5, 5}));
  EXPECT_EQ(ShiftForReaction(v, 4), (std::vector<double>{5, 5, 5, 5, 5}));
  EXPECT_EQ(ShiftForReaction(v, 9), (std::vector<double>{5, 5, 5, 5, 5}));
}

TEST(AnnotationWarp, ShiftForReactionRandom) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-5, 5);
  for (int rep = 0; rep < 300; ++rep) {
    const int n = std::uniform_int_distribution<int>(1, 60)(rng);
    const int shift = std::uniform_int_distribution<int>(0, 20)(rng);
    std::vector<double> v(n);
    for (auto& x : v) x = u(rng);
    const auto got = ShiftForReaction(v, shift);
    ASSERT_EQ(got.size(), v.size());
    const auto want = oracle::MyShift(v, shift);
    for (int t = 0; t < n; ++t) {
      // value at t + shift belongs to t; the tail repeats the last value
      EXPECT_EQ(got[t], want[t]) << "n=" << n << " shift=" << shift << " t=" << t;
    }
  }
}

TEST(AnnotationWarp, IdentityWarpIsIdentity) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(-5, 5);
  for (int n : {1, 2, 3, 10, 97}) {
    std::vector<double> a(n);
    for (auto& x : a) x = u(rng);
    std::vector<int> w(n);
    std::iota(w.begin(), w.end(), 0);
    EXPECT_EQ(WarpAnnotation(a, w, AnnotationWarpForm::kConserving), a) << "n=" << n;
    EXPECT_EQ(WarpAnnotation(a, w, AnnotationWarpForm::kPaperLiteral), a) << "n=" << n;
  }
}

// Hand-worked: a = [1, -2, 3.5, 4, -5, 0.25] (N = 6), w = [0, 0, 1, 4, 4, 5] (n = 6).
// Source frame 0 is mapped by t = 0, 1 (N_0 = 2), frame 1 by t = 2, frames 2, 3 are skipped between
// t = 2 and t = 3, frame 4 is mapped by t = 3, 4 (N_4 = 2), frame 5 by t = 5.
//
// Conserving: t0 = a0/2 = 0.5; t1 = a0/2 = 0.5; t2 = a1 + a2 + a3 = -2 + 3.5 + 4 = 5.5;
//             t3 = a4/2 = -2.5; t4 = a4/2 = -2.5; t5 = a5 = 0.25. Sum 1.75 = sum(a).
// Literal eq. 6: t0: w1 == w0 -> a0/N_0 = 0.5; t1: w2 > w1 -> sum_{0}^{0} a = 1;
//             t2: sum_{1}^{3} a = 5.5; t3: w4 == w3 -> a4/2 = -2.5; t4: sum_{4}^{4} a = -5;
//             t5 (last, maps alone to the last source frame): a5 = 0.25.
TEST(AnnotationWarp, HandWorkedExample) {
  const std::vector<double> a = {1, -2, 3.5, 4, -5, 0.25};
  const std::vector<int> w = {0, 0, 1, 4, 4, 5};
  const auto c = WarpAnnotation(a, w, AnnotationWarpForm::kConserving);
  const std::vector<double> c_expected = {0.5, 0.5, 5.5, -2.5, -2.5, 0.25};
  ASSERT_EQ(c.size(), c_expected.size());
  for (std::size_t t = 0; t < c.size(); ++t) EXPECT_DOUBLE_EQ(c[t], c_expected[t]) << "t=" << t;

  const auto p = WarpAnnotation(a, w, AnnotationWarpForm::kPaperLiteral);
  const std::vector<double> p_expected = {0.5, 1, 5.5, -2.5, -5, 0.25};
  ASSERT_EQ(p.size(), p_expected.size());
  for (std::size_t t = 0; t < p.size(); ++t) EXPECT_DOUBLE_EQ(p[t], p_expected[t]) << "t=" << t;
}

// Hand-worked, reference longer than source: a = [3, 6, -1.5] (N = 3), w = [0, 0, 0, 1, 1, 2].
// Conserving: a0/3 x3 = 1, 1, 1; a1/2 x2 = 3, 3; a2 = -1.5 (sum 7.5 = sum(a)).
// Literal: t0, t1 (flat): 3/3 = 1, 1; t2: sum_{0}^{0} = 3; t3 (flat): 6/2 = 3; t4: sum_{1}^{1} = 6;
//          t5: -1.5.
TEST(AnnotationWarp, HandWorkedStretch) {
  const std::vector<double> a = {3, 6, -1.5};
  const std::vector<int> w = {0, 0, 0, 1, 1, 2};
  const auto c = WarpAnnotation(a, w, AnnotationWarpForm::kConserving);
  const std::vector<double> c_expected = {1, 1, 1, 3, 3, -1.5};
  ASSERT_EQ(c.size(), c_expected.size());
  for (std::size_t t = 0; t < c.size(); ++t) EXPECT_DOUBLE_EQ(c[t], c_expected[t]) << "t=" << t;
  const auto p = WarpAnnotation(a, w, AnnotationWarpForm::kPaperLiteral);
  const std::vector<double> p_expected = {1, 1, 3, 3, 6, -1.5};
  ASSERT_EQ(p.size(), p_expected.size());
  for (std::size_t t = 0; t < p.size(); ++t) EXPECT_DOUBLE_EQ(p[t], p_expected[t]) << "t=" << t;
}

// Hand-worked, compression: a = [1, 2, 3, 4, 5] (N = 5), w = [0, 3, 4] (n = 3).
// Conserving: t0 = a0 + a1 + a2 = 6; t1 = a3 = 4; t2 = a4 = 5.  Literal: the same here.
TEST(AnnotationWarp, HandWorkedSkip) {
  const std::vector<double> a = {1, 2, 3, 4, 5};
  const std::vector<int> w = {0, 3, 4};
  const std::vector<double> expected = {6, 4, 5};
  EXPECT_EQ(WarpAnnotation(a, w, AnnotationWarpForm::kConserving), expected);
  EXPECT_EQ(WarpAnnotation(a, w, AnnotationWarpForm::kPaperLiteral), expected);
}

// Hand-worked, a flat run followed by a skip: a = [1, 2, 3, 4] (N = 4), w = [0, 0, 3] (n = 3).
// Conserving: the run t = 0, 1 shares a0 (0.5 each); the skipped frames 1, 2 go to the run's last
// frame t = 1 (the frame just before the skip): t1 = 0.5 + 2 + 3 = 5.5; t2 = a3 = 4.
// Literal: t0 (flat) = a0/2 = 0.5; t1 = sum_{0}^{2} a = 6; t2 = 4.
TEST(AnnotationWarp, HandWorkedFlatThenSkip) {
  const std::vector<double> a = {1, 2, 3, 4};
  const std::vector<int> w = {0, 0, 3};
  EXPECT_EQ(WarpAnnotation(a, w, AnnotationWarpForm::kConserving),
            (std::vector<double>{0.5, 5.5, 4}));
  EXPECT_EQ(WarpAnnotation(a, w, AnnotationWarpForm::kPaperLiteral),
            (std::vector<double>{0.5, 6, 4}));
}

TEST(AnnotationWarp, ConservingConservesSumAndMatchesOracle) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(-5, 5);
  int flats = 0, skips = 0;
  for (int rep = 0; rep < 2000; ++rep) {
    const int n = std::uniform_int_distribution<int>(2, 120)(rng);
    const int N = std::uniform_int_distribution<int>(1, 200)(rng);
    std::vector<double> a(N);
    for (auto& x : a) x = (rng() % 4 == 0) ? std::round(u(rng)) : u(rng);
    const std::vector<int> w = oracle::RandomMonotoneWarp(rng, n, N);
    ASSERT_EQ(w.front(), 0);
    ASSERT_EQ(w.back(), N - 1);
    for (int t = 1; t < n; ++t) {
      flats += w[t] == w[t - 1];
      skips += w[t] > w[t - 1] + 1;
    }
    const auto got = WarpAnnotation(a, w, AnnotationWarpForm::kConserving);
    ASSERT_EQ(int(got.size()), n);
    double sum_a = 0, abs_a = 0, sum_got = 0;
    for (double x : a) sum_a += x, abs_a += std::abs(x);
    for (double x : got) sum_got += x;
    EXPECT_LE(std::abs(sum_got - sum_a), 1e-12 * std::max(1.0, abs_a))
        << "n=" << n << " N=" << N << ": warped sum " << sum_got << " vs " << sum_a;
    const auto want = oracle::MyConservingWarp(a, w);
    for (int t = 0; t < n; ++t) {
      EXPECT_LE(std::abs(got[t] - want[t]), 1e-12 * std::max(1.0, abs_a))
          << "n=" << n << " N=" << N << " t=" << t << ": " << got[t] << " vs " << want[t];
    }
    if (HasFailure()) break;
  }
  EXPECT_GT(flats, 1000);
  EXPECT_GT(skips, 1000);
}

// The literal form agrees with eq. 6 as printed on every frame but the last.
TEST(AnnotationWarp, PaperLiteralMatchesEq6) {
  std::mt19937_64 rng(14);
  std::uniform_real_distribution<double> u(-5, 5);
  for (int rep = 0; rep < 1000; ++rep) {
    const int n = std::uniform_int_distribution<int>(2, 80)(rng);
    const int N = std::uniform_int_distribution<int>(1, 120)(rng);
    std::vector<double> a(N);
    for (auto& x : a) x = u(rng);
    const std::vector<int> w = oracle::RandomMonotoneWarp(rng, n, N);
    std::vector<int> count(N, 0);
    for (int t = 0; t < n; ++t) ++count[w[t]];
    const auto got = WarpAnnotation(a, w, AnnotationWarpForm::kPaperLiteral);
    ASSERT_EQ(int(got.size()), n);
    for (int t = 0; t + 1 < n; ++t) {
      double want = 0;
      if (w[t + 1] > w[t]) {
        for (int j = w[t]; j <= w[t + 1] - 1; ++j) want += a[j];
      } else {
        want = a[w[t]] / count[w[t]];
      }
      EXPECT_NEAR(got[t], want, 1e-12 * 5 * N) << "t=" << t;
    }
    if (count[N - 1] == 1) {
      EXPECT_NEAR(got[n - 1], a[N - 1], 1e-15);
    }
    if (HasFailure()) break;
  }
}

}  // namespace
}  // namespace mmh::montage
