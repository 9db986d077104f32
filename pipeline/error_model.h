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
// so that Var x_t = σ² and Corr(x_t, x_{t+1}) = ρ. On top of that, three kinds of episode, each
// starting at a free frame with its rate and lasting a geometric number of frames with its mean
// (P(k) = (1 − 1/L)^(k−1) / L, k ≥ 1), drawn in this order on the frames the earlier kinds left:
//   losses  the frames are reported lost (the last reported pose held);
//   flips   the tracker holds the proxy's near-symmetric twin: the pose turned by flip_rotation
//           about the table's vertical and moved by flip_translation in a horizontal direction
//           (both fixed per episode; the Soldier lying on its back, tracked upside down);
//   spikes  a short wrong fit: an error rotation vector and translation drawn per episode
//           (N(0, spike_rotation_sd²) and N(0, spike_translation_sd²) per axis, proxy frame),
//           added to the AR(1) error.
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
  // Every default is measured (EstimateErrorModel) on the full-fidelity study of
  // configs/study_soldier.json: 20 animators, 60 Soldier takes, 124 487 tracked and read frames,
  // with the tracker of commit ea8e4c8 (docs/study.md, "Fidelity").
  // Pose errors (see above), per axis in the proxy frame, over the frames within the tracker's
  // success criterion.
  double translation_sd = 0.00110;  // σ_e [m]
  double rotation_sd = 0.0160;      // σ_r [rad]
  double correlation = 0.678;       // ρ, lag one, in [0, 1)
  // Flips (see above): episodes per frame, mean length [frames], rotation [rad], translation [m].
  double flip_rate = 0.00158;
  double flip_mean_frames = 23.5;
  double flip_rotation = 3.14;
  double flip_translation = 0.0061;
  // Spikes (see above): episodes per frame, mean length [frames], per-axis sizes [rad], [m].
  double spike_rate = 0.00479;
  double spike_mean_frames = 2.35;
  double spike_rotation_sd = 0.0974;
  double spike_translation_sd = 0.0056;
  // Losses: episodes per frame, mean length [frames]; their frames are reported lost.
  double loss_rate = 0.00101;
  double loss_mean_frames = 1.70;
  // Slider reading: AR(1) noise [slider units] with its lag-one correlation, a bias, and the share
  // of frames in which the block is not found.
  double slider_sd = 0.164;
  double slider_correlation = 0.0;
  double slider_bias = 0.0675;
  double slider_miss_share = 0.0;

  template <class V>
  void VisitFields(V& v) {
    v("translation_sd", translation_sd);
    v("rotation_sd", rotation_sd);
    v("correlation", correlation);
    v("flip_rate", flip_rate);
    v("flip_mean_frames", flip_mean_frames);
    v("flip_rotation", flip_rotation);
    v("flip_translation", flip_translation);
    v("spike_rate", spike_rate);
    v("spike_mean_frames", spike_mean_frames);
    v("spike_rotation_sd", spike_rotation_sd);
    v("spike_translation_sd", spike_translation_sd);
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
  std::int64_t flip_frames = 0;
  std::int64_t spike_frames = 0;
  std::int64_t lost_frames = 0;
  int flip_episodes = 0;
  int spike_episodes = 0;
  int loss_episodes = 0;
  std::int64_t slider_frames = 0;
  std::int64_t slider_missed = 0;
  double slider_rmse = 0.0;

  nlohmann::json ToJson() const;
};

// Fits the model by moments. Frames within gross_threshold_deg and gross_threshold_m (the
// tracker's success criterion) are inliers: σ is the per-axis RMS and ρ the pooled lag-one
// autocorrelation of their error components over consecutive inlier frames. Frames beyond it with
// a rotation error above 90° are flips, the others spikes; flip, spike and loss episodes are runs
// of consecutive such frames: rate = episodes / frames at risk (the frames not in an episode of
// that kind or an earlier one), mean = frames / episodes; flip_rotation and flip_translation are
// the mean error angle and distance over flip frames, the spike sizes the per-axis RMS over spike
// frames. The slider's bias, sd and lag-one correlation over found frames, miss share = missed /
// frames. The maximum-likelihood estimates of the model for a large sample.
ErrorModelEstimate EstimateErrorModel(const std::vector<TrackingObservation>& tracking,
                                      const std::vector<ReadingObservation>& readings,
                                      const ErrorModelOptions& prior = {},
                                      double gross_threshold_deg = 5.0,
                                      double gross_threshold_m = 0.01);

}  // namespace mmh::pipeline
