#include "metrics/annotation_metrics.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/annotation.h"
#include "core/cross_correlation.h"
#include "core/error.h"

namespace mmh::metrics {

namespace {

double ClippedShare(std::span<const double> values) {
  if (values.empty()) return 0.0;
  const auto clipped = std::count_if(values.begin(), values.end(),
                                     [](double v) { return std::abs(v) >= kMaxAnnotation - 1e-9; });
  return static_cast<double>(clipped) / values.size();
}

}  // namespace

AnnotationErrors CompareAnnotations(std::span<const double> truth, std::span<const double> read,
                                    int max_lag) {
  if (truth.size() != read.size()) {
    ThrowBadValue("read annotation", std::to_string(read.size()) + " values",
                  "as many as the true annotation's " + std::to_string(truth.size()));
  }
  AnnotationErrors e;
  e.frames = static_cast<int>(truth.size());
  if (truth.empty()) return e;
  double squares = 0.0, absolute = 0.0, sum = 0.0;
  for (size_t i = 0; i < truth.size(); ++i) {
    const double d = read[i] - truth[i];
    squares += d * d;
    absolute += std::abs(d);
    sum += d;
    e.max_absolute = std::max(e.max_absolute, std::abs(d));
  }
  e.rmse = std::sqrt(squares / e.frames);
  e.mean_absolute = absolute / e.frames;
  e.bias = sum / e.frames;
  e.lag_frames = CrossCorrelationLag(truth, read, max_lag);
  e.truth_clipped_share = ClippedShare(truth);
  e.read_clipped_share = ClippedShare(read);
  return e;
}

nlohmann::json ToJson(const AnnotationErrors& e) {
  return {{"frames", e.frames},
          {"rmse", e.rmse},
          {"mean_absolute", e.mean_absolute},
          {"max_absolute", e.max_absolute},
          {"bias", e.bias},
          {"lag_frames", e.lag_frames},
          {"truth_clipped_share", e.truth_clipped_share},
          {"read_clipped_share", e.read_clipped_share}};
}

}  // namespace mmh::metrics
