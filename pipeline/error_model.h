// The fast-fidelity stand-in for the sensor, the tracker and the slider reader: what the tracker
// and the slider reader would report for a ground-truth take, drawn from an error model whose
// parameters are measured on full-fidelity runs (docs/pipeline.md says how, and the test that
// checks the fast mode against the full one). Section "error_model".
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/annotation.h"
#include "core/trajectory.h"
#include "track/proxy_tracker.h"

namespace mmh::pipeline {

struct ErrorModelOptions {
  // Pose errors: per-axis stationary AR(1) processes in the proxy frame [m] and [rad], with
  // lag-one correlation `correlation` (the tracker's errors drift slowly with the view).
  double translation_sd = 0.0008;  // [m]
  double rotation_sd = 0.012;      // [rad]
  double correlation = 0.9;
  // Losses: episodes start with this rate [per frame] and last a geometric number of frames with
  // this mean; their frames are reported lost.
  double loss_rate = 0.002;
  double loss_mean_frames = 4.0;
  // Slider reading: Gaussian noise [slider units], a bias, and the share of frames not found
  // (the last value held).
  double slider_sd = 0.12;
  double slider_bias = 0.0;
  double slider_miss_share = 0.002;

  template <class V>
  void VisitFields(V& v) {
    v("translation_sd", translation_sd);
    v("rotation_sd", rotation_sd);
    v("correlation", correlation);
    v("loss_rate", loss_rate);
    v("loss_mean_frames", loss_mean_frames);
    v("slider_sd", slider_sd);
    v("slider_bias", slider_bias);
    v("slider_miss_share", slider_miss_share);
  }
  void Validate(const std::string& prefix) const;
};

struct SimulatedTracking {
  Trajectory tracked;  // table_T_proxy, #frames (poses of lost frames unspecified)
  std::vector<track::TrackStatus> status;  // #frames
};

// What the tracker reports for `truth` (table_T_proxy). Deterministic in `seed`.
SimulatedTracking SimulateTracking(const Trajectory& truth, const ErrorModelOptions& options,
                                   std::uint64_t seed);

struct SimulatedReading {
  Annotation read;          // #frames, in [-5, 5], the last value held where not found
  std::vector<bool> found;  // #frames
};

// What the slider reader reports for the block's true values. Deterministic in `seed`.
SimulatedReading SimulateSliderReading(const Annotation& truth, const ErrorModelOptions& options,
                                       std::uint64_t seed);

}  // namespace mmh::pipeline
