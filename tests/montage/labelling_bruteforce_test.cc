// Oracle: exhaustive enumeration of every labelling of tiny instances (eqs. 7, 11, 12).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "montage/labelling.h"
#include "tests/montage/labelling_problem.h"
#include "tests/montage/oracles.h"

namespace mmh::montage {
namespace {

using oracle::NearRel;

std::string Describe(const oracle::Problem& p, double mu, int d) {
  std::ostringstream os;
  os.precision(17);
  os << "n=" << p.n << " m=" << p.m << " d=" << d << " mu=" << mu << "\n data(t,l):";
  for (int t = 0; t < p.n; ++t) {
    os << " [";
    for (int l = 0; l < p.m; ++l) os << (l ? "," : "") << p.D(t, l);
    os << "]";
  }
  os << "\n trans(t,l,k):";
  for (int t = 0; t + 1 < p.n; ++t) {
    os << " t" << t << "{";
    for (int l = 0; l < p.m; ++l)
      for (int k = 0; k < p.m; ++k) os << (l || k ? "," : "") << p.S(t, l, k);
    os << "}";
  }
  return os.str();
}

std::string LabelsString(const std::vector<int>& labels) {
  std::string s;
  for (int l : labels) s += std::to_string(l);
  return s;
}

oracle::Problem RandomProblem(std::mt19937_64& rng, int n, int m) {
  oracle::Problem p;
  p.n = n;
  p.m = m;
  std::uniform_int_distribution<int> mode_d(0, 3), mode_s(0, 3);
  const int dm = mode_d(rng), sm = mode_s(rng);
  std::uniform_real_distribution<double> ureal(-5.0, 5.0);
  std::uniform_int_distribution<int> uint3(-3, 3);
  p.data.resize(std::size_t(n) * m);
  const double constant = ureal(rng);
  for (auto& v : p.data) {
    switch (dm) {
      case 0:
        v = ureal(rng);
        break;
      case 1:
        v = uint3(rng);
        break;  // many ties
      case 2:
        v = constant;
        break;  // all equal
      default:
        v = (rng() % 2) ? double(uint3(rng)) : ureal(rng);
        break;
    }
  }
  std::uniform_real_distribution<double> upos(0.0, 2.0);
  std::uniform_int_distribution<int> uint2(0, 2);
  p.trans.assign(std::size_t(std::max(0, n - 1)) * m * m, 0.0);
  for (int t = 0; t + 1 < n; ++t)
    for (int l = 0; l < m; ++l)
      for (int k = 0; k < m; ++k) {
        double v = 0;
        if (l != k) {
          switch (sm) {
            case 0:
              v = upos(rng);
              break;
            case 1:
              v = uint2(rng);
              break;
            case 2:
              v = 0.0;
              break;
            default:
              v = (rng() % 3 == 0) ? 0.0 : upos(rng) * upos(rng);
              break;
          }
        }
        p.trans[(std::size_t(t) * m + l) * m + k] = v;
      }
  return p;
}

double RandomMu(std::mt19937_64& rng) {
  static const double choices[] = {0.0, 0.5, 1.0, 3.0, 100.0};
  const int c = int(rng() % 6);
  if (c < 5) return choices[c];
  return std::uniform_real_distribution<double>(0.0, 10.0)(rng);
}

TEST(LabellingBruteForce, MatchesExhaustiveEnumeration) {
  std::mt19937_64 rng(20140426);
  int checked_feasible = 0, checked_infeasible = 0;
  for (int instance = 0; instance < 3000; ++instance) {
    const int n = std::uniform_int_distribution<int>(1, 9)(rng);
    const int m = std::uniform_int_distribution<int>(1, 3)(rng);
    const int d = std::uniform_int_distribution<int>(0, 4)(rng);
    const oracle::Problem p = RandomProblem(rng, n, m);
    const double mu = RandomMu(rng);
    SCOPED_TRACE("instance " + std::to_string(instance) + ": " + Describe(p, mu, d));

    // Enumerate all m^n labellings.
    double best_feasible = oracle::kInf;
    std::string best_labels;
    std::vector<int> labels(n, 0);
    while (true) {
      if (oracle::Feasible(labels, d)) {
        const double c = oracle::Evaluate(p, labels, mu).total;
        if (c < best_feasible) {
          best_feasible = c;
          best_labels = LabelsString(labels);
        }
      }
      int i = 0;
      while (i < n && ++labels[i] == m) labels[i++] = 0;
      if (i == n) break;
    }
    double best_single = oracle::kInf;
    for (int l = 0; l < m; ++l) {
      best_single = std::min(best_single, oracle::Evaluate(p, std::vector<int>(n, l), mu).total);
    }

    LabellingOptions options;
    options.mu = mu;
    options.min_segment_length = d;
    const LabellingProblem problem = ToLabellingProblem(p);
    const LabellingResult r = SolveLabelling(problem, options);

    ASSERT_EQ(int(r.labels.size()), n);
    for (int l : r.labels) ASSERT_TRUE(l >= 0 && l < m) << "label out of range: " << l;
    const oracle::Eval mine = oracle::Evaluate(p, r.labels, mu);
    EXPECT_TRUE(NearRel(mine.total, r.total_cost))
        << "recomputed total " << mine.total << " vs result.total_cost " << r.total_cost
        << " labels " << LabelsString(r.labels);
    EXPECT_TRUE(NearRel(mine.data, r.data_cost)) << mine.data << " vs " << r.data_cost;
    EXPECT_TRUE(NearRel(mine.smooth, r.smoothness_cost))
        << mine.smooth << " vs " << r.smoothness_cost;
    EXPECT_TRUE(NearRel(r.data_cost + r.smoothness_cost, r.total_cost))
        << r.data_cost << " + " << r.smoothness_cost << " != " << r.total_cost;

    const bool any_feasible = best_feasible < oracle::kInf;
    EXPECT_EQ(any_feasible, n > d);  // self-check of the oracle
    if (any_feasible) {
      ++checked_feasible;
      EXPECT_TRUE(r.feasible) << "a feasible labelling exists, e.g. " << best_labels;
      EXPECT_TRUE(oracle::Feasible(r.labels, d))
          << "returned labels " << LabelsString(r.labels) << " violate d=" << d;
      EXPECT_TRUE(NearRel(r.total_cost, best_feasible))
          << "optimum " << best_feasible << " (" << best_labels << "), got " << r.total_cost << " ("
          << LabelsString(r.labels) << ")";
    } else {
      ++checked_infeasible;
      EXPECT_FALSE(r.feasible);
      bool single = true;
      for (int l : r.labels) single = single && l == r.labels[0];
      EXPECT_TRUE(single) << "infeasible result should be a single take, got "
                          << LabelsString(r.labels);
      EXPECT_TRUE(NearRel(r.total_cost, best_single))
          << "best single take " << best_single << ", got " << r.total_cost;
    }

    // EvaluateLabelling on a few random labellings.
    for (int rep = 0; rep < 3; ++rep) {
      std::vector<int> random_labels(n);
      for (int& l : random_labels) l = int(rng() % m);
      const LabellingResult e = EvaluateLabelling(problem, random_labels, mu);
      const oracle::Eval o = oracle::Evaluate(p, random_labels, mu);
      EXPECT_TRUE(NearRel(e.total_cost, o.total, 1e-12)) << e.total_cost << " vs " << o.total;
      EXPECT_TRUE(NearRel(e.data_cost, o.data, 1e-12)) << e.data_cost << " vs " << o.data;
      EXPECT_TRUE(NearRel(e.smoothness_cost, o.smooth, 1e-12))
          << e.smoothness_cost << " vs " << o.smooth;
      if (!e.labels.empty()) {
        EXPECT_EQ(e.labels, random_labels);
      }
    }
    if (HasFailure()) break;  // one fully described failing instance is enough
  }
  EXPECT_GT(checked_feasible, 1000);
  EXPECT_GT(checked_infeasible, 100);
}

// Longer two-take instances (up to 2^13 labellings each), where several segments fit.
TEST(LabellingBruteForce, LongerTwoTakeInstances) {
  std::mt19937_64 rng(1998);
  for (int instance = 0; instance < 400; ++instance) {
    const int n = std::uniform_int_distribution<int>(10, 13)(rng);
    const int m = 2;
    const int d = std::uniform_int_distribution<int>(0, 5)(rng);
    const oracle::Problem p = RandomProblem(rng, n, m);
    const double mu = RandomMu(rng);
    SCOPED_TRACE("instance " + std::to_string(instance) + ": " + Describe(p, mu, d));
    double best = oracle::kInf;
    for (int code = 0; code < (1 << n); ++code) {
      std::vector<int> labels(n);
      for (int t = 0; t < n; ++t) labels[t] = (code >> t) & 1;
      if (oracle::Feasible(labels, d)) best = std::min(best, oracle::Evaluate(p, labels, mu).total);
    }
    LabellingOptions options;
    options.mu = mu;
    options.min_segment_length = d;
    const LabellingResult r = SolveLabelling(ToLabellingProblem(p), options);
    EXPECT_TRUE(r.feasible);
    EXPECT_TRUE(oracle::Feasible(r.labels, d)) << LabelsString(r.labels);
    EXPECT_TRUE(NearRel(r.total_cost, best)) << "optimum " << best << ", got " << r.total_cost;
    EXPECT_TRUE(NearRel(oracle::Evaluate(p, r.labels, mu).total, r.total_cost));
    if (HasFailure()) break;
  }
}

TEST(LabellingBruteForce, SegmentsOfMatchesRunSplitting) {
  std::mt19937_64 rng(7);
  EXPECT_TRUE(SegmentsOf({}).empty());
  for (int rep = 0; rep < 2000; ++rep) {
    const int n = std::uniform_int_distribution<int>(1, 25)(rng);
    const int m = std::uniform_int_distribution<int>(1, 4)(rng);
    std::vector<int> labels(n);
    // Sticky random labels so that runs of various lengths occur.
    labels[0] = int(rng() % m);
    for (int t = 1; t < n; ++t) labels[t] = (rng() % 3 == 0) ? int(rng() % m) : labels[t - 1];
    const auto runs = oracle::Runs(labels);
    const auto segs = SegmentsOf(labels);
    ASSERT_EQ(segs.size(), runs.size()) << LabelsString(labels);
    for (std::size_t i = 0; i < runs.size(); ++i) {
      EXPECT_EQ(segs[i].label, runs[i].label) << LabelsString(labels) << " segment " << i;
      EXPECT_EQ(segs[i].first, runs[i].first) << LabelsString(labels) << " segment " << i;
      EXPECT_EQ(segs[i].last, runs[i].last) << LabelsString(labels) << " segment " << i;
      EXPECT_EQ(segs[i].length(), runs[i].last - runs[i].first + 1);
    }
    if (HasFailure()) break;
  }
}

// A hand-worked case where the constraint changes the answer.
//   take 0 costs 0 everywhere; take 1 costs [1, 1, -5, 1, 1]; mu = 0.
//   d = 0: 0 0 1 0 0 (cost -5). d = 2: runs must have >= 3 frames, so 5 frames cannot be split:
//   all 0 (cost 0) or all 1 (cost -1) -> all 1.
TEST(LabellingBruteForce, HandWorkedConstraint) {
  oracle::Problem p;
  p.n = 5;
  p.m = 2;
  p.data = {0, 1, 0, 1, 0, -5, 0, 1, 0, 1};
  p.trans.assign(4 * 4, 0.0);
  for (int t = 0; t < 4; ++t) {
    p.trans[(t * 2 + 0) * 2 + 1] = 0.25;
    p.trans[(t * 2 + 1) * 2 + 0] = 0.25;
  }
  const LabellingProblem problem = ToLabellingProblem(p);
  LabellingOptions options;
  options.mu = 0.0;
  options.min_segment_length = 0;
  LabellingResult r = SolveLabelling(problem, options);
  EXPECT_EQ(r.labels, (std::vector<int>{0, 0, 1, 0, 0}));
  EXPECT_DOUBLE_EQ(r.total_cost, -5.0);
  EXPECT_TRUE(r.feasible);

  // With mu = 1 the two switches cost 0.5 in total: still 0 0 1 0 0 at -4.5.
  options.mu = 1.0;
  r = SolveLabelling(problem, options);
  EXPECT_EQ(r.labels, (std::vector<int>{0, 0, 1, 0, 0}));
  EXPECT_DOUBLE_EQ(r.total_cost, -4.5);
  EXPECT_DOUBLE_EQ(r.smoothness_cost, 0.5);
  EXPECT_DOUBLE_EQ(r.data_cost, -5.0);

  options.mu = 0.0;
  options.min_segment_length = 2;
  r = SolveLabelling(problem, options);
  EXPECT_EQ(r.labels, (std::vector<int>{1, 1, 1, 1, 1}));
  EXPECT_DOUBLE_EQ(r.total_cost, -1.0);
  EXPECT_TRUE(r.feasible);

  // d = 5 >= n: infeasible; best single take is take 1 (cost -1).
  options.min_segment_length = 5;
  r = SolveLabelling(problem, options);
  EXPECT_FALSE(r.feasible);
  EXPECT_EQ(r.labels, (std::vector<int>{1, 1, 1, 1, 1}));
  EXPECT_DOUBLE_EQ(r.total_cost, -1.0);
}

}  // namespace
}  // namespace mmh::montage
