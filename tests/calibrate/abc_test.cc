// Rejection ABC, its quantiles and the prior sensitivity against independent computations.
#include "calibrate/abc.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "tests/test_util.h"

namespace mmh::calibrate {
namespace {

using test_util::ErrorOf;

TEST(AbcTest, QuantileIsRsType7) {
  // R: quantile(c(1, 2, 3, 4, 10), c(0.05, 0.5, 0.95)) = 1.2, 3, 8.8
  const std::vector<double> x = {10, 2, 4, 1, 3};
  EXPECT_NEAR(Quantile(x, 0.05), 1.2, 1e-12);
  EXPECT_NEAR(Quantile(x, 0.5), 3.0, 1e-12);
  EXPECT_NEAR(Quantile(x, 0.95), 8.8, 1e-12);
  EXPECT_TRUE(std::isnan(Quantile({}, 0.5)));
}

// A grid prior over θ in [0, 1]², summaries s = (θ1, θ1 + θ2), observed (0.3, 0.8): the accepted
// simulations are exactly the nearest by the scaled distance, computed here independently by
// brute force, and the posterior centres on θ = (0.3, 0.5).
TEST(AbcTest, AcceptsTheNearestSimulationsAndCentresOnTheTruth) {
  std::vector<Simulation> sims;
  for (int i = 0; i <= 40; ++i) {
    for (int j = 0; j <= 40; ++j) {
      const double a = i / 40.0, b = j / 40.0;
      sims.push_back({{a, b}, {a, a + b, std::nullopt}});
    }
  }
  const std::vector<std::pair<int, double>> fit = {{0, 0.3}, {1, 0.8}};
  AbcOptions options;
  options.accept_fraction = 0.01;
  options.regression_adjustment = false;
  const AbcResult r = RejectionAbc(sims, fit, options);
  ASSERT_EQ(r.accepted.size(), 17u);  // round(0.01 * 1681)
  // Brute force: MADs (× 1.4826) of a uniform grid's marginals, then the 17 nearest.
  auto mad = [&](int k) {
    std::vector<double> v;
    for (const auto& s : sims) v.push_back(*s.values[k]);
    std::sort(v.begin(), v.end());
    const double median = v[v.size() / 2];
    for (double& x : v) x = std::abs(x - median);
    std::sort(v.begin(), v.end());
    return 1.4826 * v[v.size() / 2];
  };
  const double m0 = mad(0), m1 = mad(1);
  EXPECT_NEAR(r.scales[0], m0, 1e-12);
  EXPECT_NEAR(r.scales[1], m1, 1e-12);
  std::vector<int> order(sims.size());
  std::iota(order.begin(), order.end(), 0);
  auto d = [&](int i) {
    return std::hypot((*sims[i].values[0] - 0.3) / m0, (*sims[i].values[1] - 0.8) / m1);
  };
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return d(a) < d(b); });
  for (std::size_t k = 0; k < r.accepted.size(); ++k) {
    EXPECT_NEAR(r.distances[r.accepted[k]], d(order[k]), 1e-12);
  }
  EXPECT_NEAR(r.posterior[0].median, 0.3, 0.03);
  EXPECT_NEAR(r.posterior[1].median, 0.5, 0.03);
  EXPECT_LE(r.posterior[0].q05, 0.3);
  EXPECT_GE(r.posterior[0].q95, 0.3);
  // The summaries are linear in θ without noise: the regression adjustment (Beaumont et al. 2002)
  // moves every accepted θ onto the truth exactly.
  options.regression_adjustment = true;
  const AbcResult adjusted = RejectionAbc(sims, fit, options, {0, 0}, {1, 1});
  EXPECT_EQ(adjusted.accepted, r.accepted);
  for (const auto& theta : adjusted.accepted_params) {
    EXPECT_NEAR(theta[0], 0.3, 1e-9);
    EXPECT_NEAR(theta[1], 0.5, 1e-9);
  }
  EXPECT_NEAR(adjusted.posterior[1].q95 - adjusted.posterior[1].q05, 0.0, 1e-9);
}

TEST(AbcTest, SimulationsMissingAFitStatisticAreNeverAccepted) {
  std::vector<Simulation> sims = {{{0.1}, {std::nullopt}}, {{0.2}, {0.5}}, {{0.3}, {0.6}}};
  const AbcResult r = RejectionAbc(sims, {{0, 0.5}}, AbcOptions{.accept_fraction = 1.0});
  EXPECT_EQ(r.accepted, (std::vector<int>{1, 2}));
  EXPECT_TRUE(std::isnan(r.distances[0]));
  sims.resize(2);
  EXPECT_NE(ErrorOf([&] { RejectionAbc(sims, {{0, 0.5}}, {}); }).find("at least 2"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { AbcOptions{.accept_fraction = 0}.Validate("calibration.abc"); })
                .find("calibration.abc.accept_fraction"),
            std::string::npos);
}

// Resampling cells that are all alike cannot move the estimate; different cells do, reproducibly.
TEST(AbcTest, BootstrapMediansMeasureTheEstimatesMonteCarloError) {
  // 10 cells of 2 replicates; the summary s = θ + noise, the observed value 0.5.
  std::vector<Simulation> varied, alike;
  std::vector<int> cell_of;
  for (int c = 0; c < 10; ++c) {
    for (int r = 0; r < 2; ++r) {
      const double theta = 0.1 * c;
      varied.push_back({{theta}, {theta + 0.03 * (r == 0 ? 1 : -1) * ((c % 3) - 1)}});
      alike.push_back({{0.4 + 0.1 * r}, {0.46 + 0.12 * r}});
      cell_of.push_back(c);
    }
  }
  const AbcOptions options{.accept_fraction = 0.5, .regression_adjustment = false};
  const auto same = BootstrapMedians(alike, cell_of, {{0, 0.5}}, options, {0}, {1}, 20, 1);
  ASSERT_EQ(same.size(), 20u);
  const double full = RejectionAbc(alike, {{0, 0.5}}, options, {0}, {1}).posterior[0].median;
  for (const auto& m : same) EXPECT_DOUBLE_EQ(m[0], full);
  const auto a = BootstrapMedians(varied, cell_of, {{0, 0.5}}, options, {0}, {1}, 50, 7);
  const auto b = BootstrapMedians(varied, cell_of, {{0, 0.5}}, options, {0}, {1}, 50, 7);
  EXPECT_EQ(a, b);
  double lo = 1, hi = 0;
  for (const auto& m : a) lo = std::min(lo, m[0]), hi = std::max(hi, m[0]);
  EXPECT_GT(hi, lo);
  EXPECT_NE(ErrorOf([&] { BootstrapMedians(varied, {0, 1}, {{0, 0.5}}, options, {0}, {1}, 5, 1); })
                .find("one per simulation"),
            std::string::npos);
}

// Accepted θ0 in [0.2, 0.4] and θ1 in [0.9, 1.0]: the box is that range ± 10 % of it, cut at the
// prior; θ2 constant keeps its prior.
TEST(AbcTest, NarrowedPriorIsTheAcceptedRangeWithAMarginInsideThePrior) {
  const std::vector<std::vector<double>> accepted = {
      {0.3, 0.95, 2.0}, {0.2, 1.0, 2.0}, {0.4, 0.9, 2.0}, {0.25, 0.97, 2.0}};
  const auto box = NarrowedPrior(accepted, {0.0, 0.0, 1.0}, {1.0, 1.0, 3.0}, 0.1);
  ASSERT_EQ(box.size(), 3u);
  EXPECT_NEAR(box[0].first, 0.18, 1e-12);
  EXPECT_NEAR(box[0].second, 0.42, 1e-12);
  EXPECT_NEAR(box[1].first, 0.89, 1e-12);
  EXPECT_DOUBLE_EQ(box[1].second, 1.0);  // 1.01 cut at the prior's bound
  EXPECT_EQ(box[2], std::make_pair(1.0, 3.0));
  // Every accepted value lies in its box (margin 0: exactly the range).
  const auto tight = NarrowedPrior(accepted, {0.0, 0.0, 1.0}, {1.0, 1.0, 3.0}, 0.0);
  for (const auto& theta : accepted) {
    for (std::size_t j = 0; j < theta.size(); ++j) {
      EXPECT_GE(theta[j], tight[j].first);
      EXPECT_LE(theta[j], tight[j].second);
    }
  }
  EXPECT_DOUBLE_EQ(tight[0].first, 0.2);
  EXPECT_DOUBLE_EQ(tight[0].second, 0.4);
  EXPECT_NE(ErrorOf([&] { NarrowedPrior(accepted, {0, 0, 1}, {1, 1, 3}, -0.1); })
                .find("calibration.next_round.margin"),
            std::string::npos);
}

// s0 = 2 θ0 exactly: standardised coefficient 1 on θ0, 0 on θ1, R² 1; s1 = θ1²: θ1 alone.
TEST(AbcTest, PriorSensitivityFindsWhichParameterMovesWhichStatistic) {
  std::vector<Simulation> sims;
  for (int i = 0; i < 11; ++i) {
    for (int j = 0; j < 11; ++j) {
      const double a = i / 10.0, b = j / 10.0;
      sims.push_back({{a, b}, {2 * a, b * b}});
    }
  }
  const Sensitivity s = PriorSensitivity(sims, 2);
  EXPECT_NEAR(s.coefficients[0][0], 1.0, 1e-9);
  EXPECT_NEAR(s.coefficients[0][1], 0.0, 1e-9);
  EXPECT_NEAR(s.r_squared[0], 1.0, 1e-9);
  EXPECT_NEAR(s.coefficients[1][0], 0.0, 1e-9);
  EXPECT_GT(s.coefficients[1][1], 0.9);
  EXPECT_EQ(s.samples[0], 121);
}

}  // namespace
}  // namespace mmh::calibrate
