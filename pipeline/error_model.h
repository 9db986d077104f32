// The fast-fidelity stand-in for the sensor, the tracker and the slider reader: what the tracker
// and the slider reader would report for a ground-truth take, drawn from an error model whose
// parameters are measured on full-fidelity runs (EstimateErrorModel below; docs/study.md,
// "Fidelity", says how the defaults were measured, and a test checks the fast mode against the
// full one). Section "error_model".
//
// Pose error of frame t: tracked_t = truth_t * proxy_T_error_t, proxy_T_error_t =
// (Exp(r_t), e_t) with r_t (rotation vector [rad]) and e_t (translation [m]) in the proxy frame,
// each of the six components an independent stationary AR(1) process
//   x_{t+1} = ρ x_t + sqrt(1 − ρ²) σ n_t,  n_t ~ N(0, 1),  x_0 ~ N(0, σ²),
// so that Var x_t = σ² and Corr(x_t, x_{t+1}) = ρ. On top of that, gross-error episodes (the
// tracker locked onto the proxy's near-symmetric twin: a half turn about the table's vertical)
// and loss episodes, each starting at a frame with its rate and lasting a geometric number of
// frames with its mean (P(k) = (1 − 1/L)^(k−1) / L, k ≥ 1).
//
// Slider reading: read_t = clamp(truth_t + bias + s_t, −5, 5), s_t an AR(1) process like the
// above (sd slider_sd, lag-one correlation slider_correlation); a frame is not found with
// probability slider_miss_share, and then the last found value is held (the first found value
// before any is found).
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/annotation.h"
#include "core/trajectory.h"
#include "track/proxy_tracker.h"

namespace mmh::pipeline {

struct ErrorModelOptions {
  // Pose errors (see above), per axis in the proxy frame. Defaults: measured on full-fidelity
  // Soldier runs (docs/study.md, "Fidelity"), frames within the tracker's success criterion.
  double translation_sd = 0.0005;  // σ_e [m]
  double rotation_sd = 0.0075;     // σ_r [rad]
  double correlation = 0.8;        // ρ, lag one, in [0, 1)
  // Gross errors: episodes per frame (at frames not already in an episode), their mean length
  // [frames], and the rotation error they carry [rad] about the table's vertical (π: the twin).
  double gross_rate = 0.0005;
  double gross_mean_frames = 5.0;
  double gross_rotation = 3.14159265358979323846;
  // Losses: episodes per frame, mean length [frames]; their frames are reported lost.
  double loss_rate = 0.001;
  double loss_mean_frames = 4.0;
  // Slider reading: AR(1) noise [slider units] with its lag-one correlation, a bias, and the share
  // of frames in which the block is not found.
  double slider_sd = 0.12;
  double slider_correlation = 0.5;
  double slider_bias = 0.0;
  double slider_miss_share = 0.002;

  template <class V>
  void VisitFields(V& v) {
    v("translation_sd", translation_sd);
    v("rotation_sd", rotation_sd);
    v("correlation", correlation);
    v("gross_rate", gross_rate);
    v("gross_mean_frames", gross_mean_frames);
    v("gross_rotation", gross_rotation);
    v("loss_rate", loss_rate);
    v("loss_mean_frames", loss_mean_frames);
    v("slider_sd", slider_sd);
    v("slider_correlation", slider_correlation);
    v("slider_bias", slider_bias);
    v("slider_miss_share", slider_miss_share);
  }
  void Validate(const std::string& prefix) const;
};

struct SimulatedTracking {
  Trajectory tracked;  // table_T_proxy, #frames (lost frames: the last reported pose held)
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

// ---- Measuring the model on full-fidelity runs -------------------------------------------------

// One tracked take against its ground truth (all #frames).
struct TrackingObservation {
  const Trajectory* truth = nullptr;    // table_T_proxy
  const Trajectory* tracked = nullptr;  // table_T_proxy as reported
  const std::vector<track::TrackStatus>* status = nullptr;
};

// One slider reading against the block's true values (all #frames).
struct ReadingObservation {
  const Annotation* truth = nullptr;
  const Annotation* read = nullptr;
  const std::vector<bool>* found = nullptr;
};

struct ErrorModelEstimate {
  ErrorModelOptions options;  // the fitted model (fields without data keep `prior`'s values)
  std::int64_t frames = 0;    // tracked frames observed
  std::int64_t inlier_frames = 0;
  std::int64_t gross_frames = 0;
  std::int64_t lost_frames = 0;
  int gross_episodes = 0;
  int loss_episodes = 0;
  std::int64_t slider_frames = 0;
  std::int64_t slider_missed = 0;
  double slider_rmse = 0.0;

  nlohmann::json ToJson() const;
};

// Fits the model by moments: σ as the per-axis RMS and ρ as the pooled lag-one autocorrelation of
// the error components over consecutive inlier frames (within gross_threshold_deg and
// gross_threshold_m, the tracker's success criterion); gross and loss episodes as runs of
// consecutive frames beyond the threshold or lost, rate = episodes / frames at risk, mean = frames
// / episodes; the slider's bias, sd and lag-one correlation over found frames, miss share =
// missed / frames. The maximum-likelihood estimates of the model for a large sample.
ErrorModelEstimate EstimateErrorModel(const std::vector<TrackingObservation>& tracking,
                                      const std::vector<ReadingObservation>& readings,
                                      const ErrorModelOptions& prior = {},
                                      double gross_threshold_deg = 5.0,
                                      double gross_threshold_m = 0.01);

}  // namespace mmh::pipeline
