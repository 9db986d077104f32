// The step law's fit against a brute-force least-absolute-deviations search, on runs drawn from
// known lines, and its runs against images with known shadows and occlusions.
#include "sim/step_law.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "core/error.h"

namespace mmh::sim {
namespace {

// Runs on the line length = slope x + intercept, x spread over [min_x, max_x], with Laplace
// noise of scale `noise` and a share `outliers` of runs lengthened by up to 30 px.
std::vector<StepRun> LineRuns(int n, double slope_m, double intercept_px, double noise,
                              double outliers, unsigned seed, double min_x = 50,
                              double max_x = 600) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> x(min_x, max_x), unit(0, 1);
  std::exponential_distribution<double> laplace(1.0);
  std::vector<StepRun> runs;
  for (int i = 0; i < n; ++i) {
    StepRun r;
    r.step_px_per_m = x(rng);
    r.length_px = slope_m * r.step_px_per_m + intercept_px;
    if (noise > 0) r.length_px += (unit(rng) < 0.5 ? -1 : 1) * noise * laplace(rng);
    if (unit(rng) < outliers) r.length_px += 30 * unit(rng);
    runs.push_back(r);
  }
  return runs;
}

// The least-absolute-deviations optimum passes through two of the points (a vertex of the
// linear programme): the smallest objective over the lines through every pair.
double BruteForceLeastAbsoluteDeviation(const std::vector<StepRun>& runs) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < runs.size(); ++i) {
    for (size_t j = i + 1; j < runs.size(); ++j) {
      const double dx = runs[j].step_px_per_m - runs[i].step_px_per_m;
      if (dx == 0) continue;
      const double slope = (runs[j].length_px - runs[i].length_px) / dx;
      const double intercept = runs[i].length_px - slope * runs[i].step_px_per_m;
      best = std::min(best, AbsoluteDeviation(runs, slope, intercept));
    }
  }
  return best;
}

TEST(StepLaw, FitIsTheLeastAbsoluteDeviationsLineOfBruteForce) {
  StepLawOptions options;
  options.min_step_px_per_m = 0;
  options.bootstrap_samples = 0;
  for (unsigned seed = 1; seed <= 12; ++seed) {
    const std::vector<StepRun> runs =
        LineRuns(10 + 3 * static_cast<int>(seed), 0.05, 1.5, 2.0, 0.2, seed);
    const StepLaw law = FitStepLaw(runs, options);
    const double brute = BruteForceLeastAbsoluteDeviation(runs);
    const double fitted = AbsoluteDeviation(runs, law.slope_m, law.intercept_px);
    EXPECT_LE(fitted, brute + 1e-6) << "seed " << seed;
    EXPECT_GE(fitted, brute - 1e-6) << "seed " << seed;  // brute force is the optimum
  }
}

TEST(StepLaw, RunsOnALineGiveItsSlopeAndIntercept) {
  const std::vector<StepRun> runs = LineRuns(200, 0.0382, 2.1, 0.0, 0.0, 7);
  const StepLaw law = FitStepLaw(runs);
  EXPECT_EQ(law.runs, 200);
  EXPECT_NEAR(law.slope_m, 0.0382, 1e-8);
  EXPECT_NEAR(law.intercept_px, 2.1, 1e-5);
  // Every resample lies on the same line.
  EXPECT_NEAR(law.slope_low_m, 0.0382, 1e-8);
  EXPECT_NEAR(law.slope_high_m, 0.0382, 1e-8);
  EXPECT_GT(law.step_p90_px_per_m, law.step_p10_px_per_m);
  EXPECT_GE(law.step_p10_px_per_m, 50);
  EXPECT_LE(law.step_p90_px_per_m, 600);
}

TEST(StepLaw, OutliersDoNotMoveTheFitAndTheIntervalCoversTheSlope) {
  // A third of the runs lengthened (a hole beside the shadow): least squares would follow them.
  const std::vector<StepRun> runs = LineRuns(600, 0.05, 1.0, 0.7, 0.33, 3);
  const StepLaw law = FitStepLaw(runs);
  EXPECT_NEAR(law.slope_m, 0.05, 0.004);
  EXPECT_LT(law.slope_low_m, law.slope_m);
  EXPECT_GT(law.slope_high_m, law.slope_m);
  EXPECT_LT(law.slope_low_m, 0.05);
  EXPECT_GT(law.slope_high_m, 0.05);
  EXPECT_LT(law.slope_high_m - law.slope_low_m, 0.01);
}

TEST(StepLaw, TheIntervalDependsOnTheSeedAlone) {
  const std::vector<StepRun> runs = LineRuns(300, 0.05, 1.0, 1.5, 0.1, 11);
  StepLawOptions options;
  const StepLaw a = FitStepLaw(runs, options), b = FitStepLaw(runs, options);
  EXPECT_EQ(a.slope_low_m, b.slope_low_m);
  EXPECT_EQ(a.slope_high_m, b.slope_high_m);
  options.seed = 2;
  const StepLaw c = FitStepLaw(runs, options);
  EXPECT_EQ(c.slope_m, a.slope_m);  // the fit itself draws nothing
  EXPECT_NE(c.slope_low_m, a.slope_low_m);
}

TEST(StepLaw, SmallStepsAndTooFewRunsAreLeftOut) {
  std::vector<StepRun> runs = LineRuns(30, 0.05, 1.0, 0.0, 0.0, 5, 50, 600);
  // Small steps whose runs are the window's alone: left out below min_step_px_per_m.
  for (int i = 0; i < 50; ++i) runs.push_back({10.0 + i * 0.5, 9.0});
  const StepLaw law = FitStepLaw(runs);
  EXPECT_EQ(law.runs, 30);
  EXPECT_NEAR(law.slope_m, 0.05, 1e-8);
  StepLawOptions options;
  options.min_runs = 31;
  const StepLaw none = FitStepLaw(runs, options);
  EXPECT_EQ(none.runs, 30);
  EXPECT_TRUE(std::isnan(none.slope_m));
  EXPECT_TRUE(std::isnan(none.slope_low_m));
  // All at one step: no line.
  const StepLaw flat = FitStepLaw(std::vector<StepRun>(20, StepRun{100.0, 5.0}));
  EXPECT_TRUE(std::isnan(flat.slope_m));
  EXPECT_EQ(FitStepLaw(std::vector<StepRun>{}).runs, 0);
}

TEST(StepLaw, ARangeOfStepsIsFittedOnItsOwn) {
  // Small steps on one line, large ones on another (a matcher that fills part of wide shadows):
  // the whole range follows neither; each range alone gives its own.
  std::vector<StepRun> runs = LineRuns(300, 0.055, -0.6, 0.3, 0.0, 21, 40, 200);
  const std::vector<StepRun> large = LineRuns(300, 0.04, -2.0, 0.3, 0.0, 22, 450, 700);
  runs.insert(runs.end(), large.begin(), large.end());
  StepLawOptions small;
  small.max_step_px_per_m = 200;
  const StepLaw law = FitStepLaw(runs, small);
  EXPECT_EQ(law.runs, 300);
  EXPECT_NEAR(law.slope_m, 0.055, 0.002);
  EXPECT_NEAR(law.intercept_px, -0.6, 0.3);
  EXPECT_LE(law.step_p90_px_per_m, 200);
  StepLawOptions wide;
  wide.min_step_px_per_m = 400;
  EXPECT_NEAR(FitStepLaw(runs, wide).slope_m, 0.04, 0.002);
  EXPECT_GT(std::abs(FitStepLaw(runs).slope_m - 0.055), 0.003);
}

TEST(StepLaw, ShadowAndEdgeRunsCarryTheirStep) {
  // A wall at 2 m; in each row a near board at z_near over columns [200, 260), a shadow of 7 px
  // left of it (the far side on the left) and an occlusion of 3 px right of it; a hole inside the
  // wall (low signal) and one at the border, which are not steps.
  constexpr int kWidth = 320, kHeight = 40;
  constexpr double kFx = 525;
  std::vector<float> depth(kWidth * kHeight, 2.0f);
  for (int v = 0; v < kHeight; ++v) {
    float* row = &depth[v * kWidth];
    const float near = 0.8f + 0.02f * v;
    for (int u = 200; u < 260; ++u) row[u] = near;
    for (int u = 193; u < 200; ++u) row[u] = 0;
    for (int u = 260; u < 263; ++u) row[u] = 0;
    for (int u = 100; u < 104; ++u) row[u] = 0;
    for (int u = 0; u < 3; ++u) row[u] = 0;
  }
  std::vector<StepRun> shadow, edge;
  CollectStepRuns(depth, kWidth, kHeight, kFx, &shadow, &edge);
  ASSERT_EQ(shadow.size(), static_cast<size_t>(kHeight));
  ASSERT_EQ(edge.size(), static_cast<size_t>(kHeight));
  for (int v = 0; v < kHeight; ++v) {
    const double near = 0.8f + 0.02f * v;
    EXPECT_NEAR(shadow[v].step_px_per_m, kFx * (1 / near - 1 / 2.0), 1e-3);
    EXPECT_EQ(shadow[v].length_px, 7);
    EXPECT_NEAR(edge[v].step_px_per_m, kFx * (1 / near - 1 / 2.0), 1e-3);
    EXPECT_EQ(edge[v].length_px, 3);
  }
  std::vector<StepRun> shadow_only;
  CollectStepRuns(depth, kWidth, kHeight, kFx, &shadow_only, nullptr);
  EXPECT_EQ(shadow_only.size(), shadow.size());
}

TEST(StepLaw, GeometricShadowsGiveTheProjectorsDistance) {
  // Shadows as a projector 4 cm from the camera casts them (rounded to whole pixels) beside
  // boards at 0.55-1.5 m before walls at 1.4-3 m, plus 1 px the matcher fails beside them.
  constexpr int kWidth = 640, kHeight = 200;
  constexpr double kFx = 525, kProjector = 0.04;
  std::vector<float> depth(kWidth * kHeight);
  for (int v = 0; v < kHeight; ++v) {
    const double near = 0.55 + 0.95 * ((v * 37) % kHeight) / kHeight;
    const double far = std::max(near + 0.1, 1.4 + 1.6 * ((v * 53) % kHeight) / kHeight);
    const int shadow = static_cast<int>(std::lround(kFx * kProjector * (1 / near - 1 / far))) + 1;
    float* row = &depth[v * kWidth];
    for (int u = 0; u < kWidth; ++u) row[u] = u < 500 - shadow ? far : (u < 500 ? 0 : near);
  }
  std::vector<StepRun> runs;
  CollectStepRuns(depth, kWidth, kHeight, kFx, &runs, nullptr);
  const StepLaw law = FitStepLaw(runs);
  EXPECT_NEAR(law.slope_m, kProjector, 0.002);
  EXPECT_NEAR(law.intercept_px, 1.0, 0.6);
  EXPECT_LT(law.slope_low_m, kProjector + 0.001);
  EXPECT_GT(law.slope_high_m, kProjector - 0.001);
}

TEST(StepLaw, BadOptionsNameTheKey) {
  const std::vector<StepRun> runs = LineRuns(20, 0.05, 1.0, 0.0, 0.0, 1);
  auto message = [&](StepLawOptions options) {
    try {
      FitStepLaw(runs, options);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  StepLawOptions o;
  o.min_runs = 1;
  EXPECT_NE(message(o).find("step_law.min_runs"), std::string::npos);
  o = {};
  o.confidence = 1.0;
  EXPECT_NE(message(o).find("step_law.confidence"), std::string::npos);
  o = {};
  o.bootstrap_samples = -1;
  EXPECT_NE(message(o).find("step_law.bootstrap_samples"), std::string::npos);
  o = {};
  o.max_step_px_per_m = o.min_step_px_per_m;
  EXPECT_NE(message(o).find("step_law.max_step_px_per_m"), std::string::npos);
  o = {};
  o.min_step_px_per_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(message(o).find("step_law.min_step_px_per_m"), std::string::npos);
  std::vector<float> depth(100, 1.0f);
  EXPECT_THROW(CollectStepRuns(depth, 10, 10, 0.0, nullptr, nullptr), InputError);
  EXPECT_THROW(CollectStepRuns(depth, 10, 9, 525.0, nullptr, nullptr), InputError);
  std::vector<StepRun> bad = runs;
  bad[3].length_px = std::numeric_limits<double>::infinity();
  EXPECT_THROW(FitStepLaw(bad), InputError);
}

}  // namespace
}  // namespace mmh::sim
