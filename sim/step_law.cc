#include "sim/step_law.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/error.h"
#include "metrics/tracking_metrics.h"
#include "sim/internal/counter_random.h"
#include "sim/internal/depth_sample.h"

namespace mmh::sim {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The slopes searched [m]: a sensor's baseline is centimetres; a fit at either end means the runs
// do not follow the law.
constexpr double kSlopeBracketM = 1.0;
// Golden-section search stops when the bracket is this narrow [m] (a thousandth of a millimetre).
constexpr double kSlopeToleranceM = 1e-9;

// The intercept that minimises sum |l - slope x - c| for a fixed slope: a median of the residuals
// (the mean of the two middle ones for an even count; every value between them is a minimiser).
double BestIntercept(std::span<const StepRun> runs, double slope_m) {
  std::vector<double> residuals(runs.size());
  for (size_t i = 0; i < runs.size(); ++i) {
    residuals[i] = runs[i].length_px - slope_m * runs[i].step_px_per_m;
  }
  return internal::Median(std::move(residuals));
}

struct Line {
  double slope_m, intercept_px;
};

// Least absolute deviations. With the intercept at its best for each slope, the objective
// F(slope) = min_c sum |l - slope x - c| is convex (the minimum over c of a jointly convex
// function), so golden-section search finds its minimum.
Line FitLeastAbsoluteDeviations(std::span<const StepRun> runs) {
  auto objective = [&](double slope) {
    return AbsoluteDeviation(runs, slope, BestIntercept(runs, slope));
  };
  const double ratio = (std::sqrt(5.0) - 1) / 2;
  double low = -kSlopeBracketM, high = kSlopeBracketM;
  double a = high - ratio * (high - low), b = low + ratio * (high - low);
  double fa = objective(a), fb = objective(b);
  while (high - low > kSlopeToleranceM) {
    if (fa <= fb) {
      high = b;
      b = a;
      fb = fa;
      a = high - ratio * (high - low);
      fa = objective(a);
    } else {
      low = a;
      a = b;
      fa = fb;
      b = low + ratio * (high - low);
      fb = objective(b);
    }
  }
  const double slope = 0.5 * (low + high);
  return {slope, BestIntercept(runs, slope)};
}

}  // namespace

void StepLawOptions::Validate(const std::string& prefix) const {
  if (!(min_step_px_per_m >= 0) || !std::isfinite(min_step_px_per_m)) {
    ThrowBadValue(prefix + ".min_step_px_per_m", FormatNumber(min_step_px_per_m),
                  "a finite step of 0 px / m or more");
  }
  if (!(max_step_px_per_m > min_step_px_per_m)) {
    ThrowBadValue(prefix + ".max_step_px_per_m", FormatNumber(max_step_px_per_m),
                  "above min_step_px_per_m (" + FormatNumber(min_step_px_per_m) + ")");
  }
  if (min_runs < 2) {
    ThrowBadValue(prefix + ".min_runs", std::to_string(min_runs), "2 or more (a line)");
  }
  if (bootstrap_samples < 0) {
    ThrowBadValue(prefix + ".bootstrap_samples", std::to_string(bootstrap_samples),
                  "0 (no interval) or more");
  }
  if (!(confidence > 0 && confidence < 1)) {
    ThrowBadValue(prefix + ".confidence", FormatNumber(confidence), "a level in (0, 1)");
  }
}

void CollectStepRuns(const std::vector<float>& depth_m, int width, int height, double fx_px,
                     std::vector<StepRun>* shadow, std::vector<StepRun>* edge,
                     const ErrorStructureOptions& options) {
  if (!(fx_px > 0) || !std::isfinite(fx_px)) {
    ThrowBadValue("fx", FormatNumber(fx_px), "a focal length above 0 px");
  }
  if (width < 1 || height < 1 || depth_m.size() != static_cast<size_t>(width) * height) {
    ThrowBadValue("depth", std::to_string(depth_m.size()) + " pixels",
                  std::to_string(width) + " x " + std::to_string(height));
  }
  // ClassifyMissing gives every pixel of a run its run's class; a run is a maximal stretch of
  // missing pixels, so its neighbours are valid (a border run has none).
  const std::vector<MissingClass> classes = ClassifyMissing(depth_m, width, height, options);
  for (int v = 0; v < height; ++v) {
    const size_t row = static_cast<size_t>(v) * width;
    for (int u = 0; u < width;) {
      const MissingClass c = classes[row + u];
      const int first = u;
      while (u < width && classes[row + u] == c) ++u;
      const bool is_shadow = c == MissingClass::kShadow;
      if (!is_shadow && c != MissingClass::kEdge) continue;
      std::vector<StepRun>* out = is_shadow ? shadow : edge;
      if (out == nullptr) continue;
      const double left = depth_m[row + first - 1], right = depth_m[row + u];
      // Shadow: the far side on the left; edge: on the right.
      const double near = is_shadow ? right : left, far = is_shadow ? left : right;
      out->push_back({fx_px * (1 / near - 1 / far), static_cast<double>(u - first)});
    }
  }
}

double AbsoluteDeviation(std::span<const StepRun> runs, double slope_m, double intercept_px) {
  double sum = 0;
  for (const StepRun& r : runs) {
    sum += std::abs(r.length_px - slope_m * r.step_px_per_m - intercept_px);
  }
  return sum;
}

StepLaw FitStepLaw(std::span<const StepRun> runs, const StepLawOptions& options) {
  options.Validate("step_law");
  std::vector<StepRun> kept;
  for (const StepRun& r : runs) {
    if (!std::isfinite(r.step_px_per_m) || !std::isfinite(r.length_px)) {
      ThrowBadValue("step_law run",
                    FormatNumber(r.step_px_per_m) + " px / m, " + FormatNumber(r.length_px) + " px",
                    "finite values");
    }
    if (r.step_px_per_m >= options.min_step_px_per_m &&
        r.step_px_per_m <= options.max_step_px_per_m) {
      kept.push_back(r);
    }
  }
  StepLaw law;
  law.runs = static_cast<int>(kept.size());
  law.slope_m = law.intercept_px = law.slope_low_m = law.slope_high_m = kNaN;
  law.step_p10_px_per_m = law.step_p90_px_per_m = kNaN;
  if (!kept.empty()) {
    std::vector<double> steps;
    for (const StepRun& r : kept) steps.push_back(r.step_px_per_m);
    law.step_p10_px_per_m = metrics::Quantile(steps, 0.1);
    law.step_p90_px_per_m = metrics::Quantile(steps, 0.9);
  }
  const auto [lowest, highest] = std::minmax_element(
      kept.begin(), kept.end(),
      [](const StepRun& a, const StepRun& b) { return a.step_px_per_m < b.step_px_per_m; });
  if (law.runs < options.min_runs || lowest->step_px_per_m == highest->step_px_per_m) return law;
  const Line line = FitLeastAbsoluteDeviations(kept);
  law.slope_m = line.slope_m;
  law.intercept_px = line.intercept_px;
  if (options.bootstrap_samples == 0) return law;
  // Resample the runs with replacement; the draws are a counter-based hash of (seed, sample,
  // draw), so the interval depends on the seed alone.
  std::vector<double> slopes;
  std::vector<StepRun> sample(kept.size());
  const uint64_t n = kept.size();
  for (int b = 0; b < options.bootstrap_samples; ++b) {
    const uint64_t key = internal::Mix64(options.seed ^ internal::Mix64(b + 1));
    for (uint64_t i = 0; i < n; ++i) sample[i] = kept[internal::Mix64(key + i) % n];
    slopes.push_back(FitLeastAbsoluteDeviations(sample).slope_m);
  }
  const double tail = (1 - options.confidence) / 2;
  law.slope_low_m = metrics::Quantile(slopes, tail);
  law.slope_high_m = metrics::Quantile(slopes, 1 - tail);
  return law;
}

nlohmann::json ToJson(const StepLaw& law) {
  auto number = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(); };
  return {{"runs", law.runs},
          {"slope_m", number(law.slope_m)},
          {"intercept_px", number(law.intercept_px)},
          {"slope_low_m", number(law.slope_low_m)},
          {"slope_high_m", number(law.slope_high_m)},
          {"step_p10_px_per_m", number(law.step_p10_px_per_m)},
          {"step_p90_px_per_m", number(law.step_p90_px_per_m)}};
}

}  // namespace mmh::sim
