// Metrics of a read annotation (the slider reader's values) against the true slider values, and
// of an annotation's timing against the opinion it expresses.
#pragma once

#include <nlohmann/json.hpp>
#include <span>

namespace mmh::metrics {

struct AnnotationErrors {
  int frames = 0;
  double rmse = 0.0;           // [slider units]
  double mean_absolute = 0.0;  // [slider units]
  double max_absolute = 0.0;   // [slider units]
  double bias = 0.0;           // mean of read − truth
  // Lag of the read values behind the truth [frames] (cross-correlation, 0..max_lag): the reader
  // should add none.
  double lag_frames = 0.0;
  // Share of frames at an end stop (|value| ≥ 5 − 1e-9).
  double truth_clipped_share = 0.0;
  double read_clipped_share = 0.0;
};

// `truth` and `read` have the same length (InputError otherwise), more than max_lag + 2 values.
AnnotationErrors CompareAnnotations(std::span<const double> truth, std::span<const double> read,
                                    int max_lag = 15);
nlohmann::json ToJson(const AnnotationErrors& errors);

}  // namespace mmh::metrics
