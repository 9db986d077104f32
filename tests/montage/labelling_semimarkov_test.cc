// Oracle: a textbook O(n^2 m^2) semi-Markov dynamic programme (explicit segment start and
// previous label, no prefix sums or running minimum) at medium sizes.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "montage/labelling.h"
#include "tests/montage/labelling_problem.h"
#include "tests/montage/oracles.h"

namespace mmh::montage {
namespace {

using oracle::NearRel;

// Annotation-like data: each take has a piecewise-constant "liking" with noise, so that the best
// take changes every few dozen frames and the constraint binds.
oracle::Problem StructuredProblem(std::mt19937_64& rng, int n, int m, bool integer_data) {
  oracle::Problem p;
  p.n = n;
  p.m = m;
  p.data.resize(std::size_t(n) * m);
  std::uniform_real_distribution<double> level(-5.0, 5.0);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_int_distribution<int> piece(5, 80);
  for (int l = 0; l < m; ++l) {
    int t = 0;
    while (t < n) {
      const int len = piece(rng);
      const double v = level(rng);
      for (int i = t; i < std::min(n, t + len); ++i) {
        double x = std::clamp(v + 0.7 * noise(rng), -5.0, 5.0);
        if (integer_data) x = std::round(x);
        p.data[std::size_t(i) * m + l] = -x;
      }
      t += len;
    }
  }
  std::uniform_real_distribution<double> u(0.0, 1.0);
  p.trans.assign(std::size_t(n - 1) * m * m, 0.0);
  for (int t = 0; t + 1 < n; ++t)
    for (int l = 0; l < m; ++l)
      for (int k = 0; k < m; ++k)
        if (l != k) p.trans[(std::size_t(t) * m + l) * m + k] = u(rng) * u(rng) * 2.0;
  return p;
}

TEST(LabellingSemiMarkov, OracleAgreesWithBruteForceOnTinyInstances) {
  // Self-check of the semi-Markov oracle against enumeration (so that the medium-size comparison
  // below rests on a verified oracle).
  std::mt19937_64 rng(99);
  for (int rep = 0; rep < 400; ++rep) {
    const int n = std::uniform_int_distribution<int>(1, 8)(rng);
    const int m = std::uniform_int_distribution<int>(1, 3)(rng);
    const int d = std::uniform_int_distribution<int>(0, 4)(rng);
    const double mu = std::uniform_real_distribution<double>(0.0, 3.0)(rng);
    oracle::Problem p;
    p.n = n;
    p.m = m;
    std::uniform_real_distribution<double> u(-2.0, 2.0), v(0.0, 1.0);
    for (int i = 0; i < n * m; ++i) p.data.push_back(u(rng));
    for (int t = 0; t + 1 < n; ++t)
      for (int l = 0; l < m; ++l)
        for (int k = 0; k < m; ++k) p.trans.push_back(l == k ? 0.0 : v(rng));
    double best = oracle::kInf;
    std::vector<int> labels(n, 0);
    while (true) {
      if (oracle::Feasible(labels, d)) best = std::min(best, oracle::Evaluate(p, labels, mu).total);
      int i = 0;
      while (i < n && ++labels[i] == m) labels[i++] = 0;
      if (i == n) break;
    }
    const double dp = oracle::SemiMarkovOptimum(p, mu, d);
    if (best == oracle::kInf) {
      ASSERT_EQ(dp, oracle::kInf);
    } else {
      ASSERT_TRUE(NearRel(best, dp, 1e-12)) << best << " vs " << dp;
    }
  }
}

TEST(LabellingSemiMarkov, MatchesTextbookDpAtMediumSize) {
  std::mt19937_64 rng(31337);
  const int ds[] = {0, 10, 30, 60};
  const double mus[] = {0.0, 0.3, 1.0, 5.0, 100.0};
  int instances = 0, multi_segment = 0;
  for (int rep = 0; rep < 12; ++rep) {
    for (int d : ds) {
      const int n = std::uniform_int_distribution<int>(150, 400)(rng);
      const int m = std::uniform_int_distribution<int>(2, 6)(rng);
      const double mu = mus[rng() % 5];
      const bool integer_data = rng() % 3 == 0;
      const oracle::Problem p = StructuredProblem(rng, n, m, integer_data);
      SCOPED_TRACE("rep " + std::to_string(rep) + " n=" + std::to_string(n) +
                   " m=" + std::to_string(m) + " d=" + std::to_string(d) +
                   " mu=" + std::to_string(mu) + (integer_data ? " integer data" : ""));

      LabellingOptions options;
      options.mu = mu;
      options.min_segment_length = d;
      const LabellingResult r = SolveLabelling(ToLabellingProblem(p), options);
      const double expected = oracle::SemiMarkovOptimum(p, mu, d);
      ++instances;

      ASSERT_EQ(int(r.labels.size()), n);
      EXPECT_TRUE(r.feasible);
      EXPECT_TRUE(NearRel(r.total_cost, expected))
          << "semi-Markov optimum " << expected << ", SolveLabelling " << r.total_cost;
      const oracle::Eval mine = oracle::Evaluate(p, r.labels, mu);
      EXPECT_TRUE(NearRel(mine.total, r.total_cost))
          << "labels evaluate to " << mine.total << ", reported " << r.total_cost;
      EXPECT_TRUE(NearRel(r.data_cost + r.smoothness_cost, r.total_cost));
      const auto runs = oracle::Runs(r.labels);
      if (runs.size() > 1) ++multi_segment;
      for (const auto& run : runs) {
        EXPECT_GT(run.last - run.first + 1, d)
            << "segment [" << run.first << ", " << run.last << "] of take " << run.label;
      }
      if (HasFailure()) return;
    }
  }
  EXPECT_EQ(instances, 48);
  EXPECT_GT(multi_segment, 20);  // the instances do exercise transitions
}

// Long, constraint-heavy instances where only a few segments fit: d close to n.
TEST(LabellingSemiMarkov, NearlyInfeasibleConstraint) {
  std::mt19937_64 rng(4242);
  for (int rep = 0; rep < 30; ++rep) {
    const int n = std::uniform_int_distribution<int>(100, 200)(rng);
    const int m = std::uniform_int_distribution<int>(2, 4)(rng);
    const int d = std::uniform_int_distribution<int>(n / 4, n - 1)(rng);
    const oracle::Problem p = StructuredProblem(rng, n, m, false);
    LabellingOptions options;
    options.mu = 1.0;
    options.min_segment_length = d;
    const LabellingResult r = SolveLabelling(ToLabellingProblem(p), options);
    const double expected = oracle::SemiMarkovOptimum(p, 1.0, d);
    EXPECT_TRUE(r.feasible);
    EXPECT_TRUE(NearRel(r.total_cost, expected))
        << "n=" << n << " m=" << m << " d=" << d << ": expected " << expected << ", got "
        << r.total_cost;
    EXPECT_TRUE(oracle::Feasible(r.labels, d));
    if (HasFailure()) return;
  }
}

}  // namespace
}  // namespace mmh::montage
