#include "metrics/trajectory_error.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "metrics/tracking_metrics.h"

namespace mmh::metrics {

namespace {

void RequireSameSize(size_t estimate, size_t reference) {
  if (estimate != reference) {
    ThrowBadValue("trajectory error", std::to_string(estimate) + " estimated poses",
                  "as many as the reference's " + std::to_string(reference));
  }
}

}  // namespace

ErrorStatistics Statistics(std::span<const double> errors) {
  ErrorStatistics s;
  s.count = static_cast<int>(errors.size());
  if (errors.empty()) return s;
  double sum = 0.0;
  for (double e : errors) sum += e, s.sse += e * e;
  s.mean = sum / s.count;
  s.rmse = std::sqrt(s.sse / s.count);
  double squares = 0.0;
  for (double e : errors) squares += (e - s.mean) * (e - s.mean);
  s.std = std::sqrt(squares / s.count);
  s.min = *std::min_element(errors.begin(), errors.end());
  s.max = *std::max_element(errors.begin(), errors.end());
  s.median = Quantile(std::vector<double>(errors.begin(), errors.end()), 0.5);
  return s;
}

nlohmann::json ToJson(const ErrorStatistics& s) {
  return {{"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median}, {"std", s.std},
          {"min", s.min},   {"max", s.max},   {"sse", s.sse},       {"count", s.count}};
}

std::vector<double> AbsoluteTranslationErrors(std::span<const Rigid3> estimate,
                                              std::span<const Rigid3> reference) {
  RequireSameSize(estimate.size(), reference.size());
  std::vector<double> errors(estimate.size());
  for (size_t i = 0; i < estimate.size(); ++i) {
    errors[i] = (reference[i].translation - estimate[i].translation).norm();
  }
  return errors;
}

RelativeErrors RelativePoseErrors(std::span<const Rigid3> estimate,
                                  std::span<const Rigid3> reference, int delta) {
  RequireSameSize(estimate.size(), reference.size());
  if (delta < 1) ThrowBadValue("RPE delta", std::to_string(delta), "at least 1 frame");
  RelativeErrors r;
  for (size_t i = 0; i + delta < estimate.size(); ++i) {
    const Rigid3 reference_step = reference[i].Inverse() * reference[i + delta];
    const Rigid3 estimate_step = estimate[i].Inverse() * estimate[i + delta];
    const Rigid3 error = reference_step.Inverse() * estimate_step;
    r.translation.push_back(error.translation.norm());
    r.rotation_deg.push_back(RotationAngle(Eigen::Quaterniond::Identity(), error.rotation) * 180.0 /
                             3.14159265358979323846);
  }
  return r;
}

}  // namespace mmh::metrics
