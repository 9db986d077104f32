// The fast-fidelity stand-in for the sensor, the tracker and the slider reader: what the tracker
// and the slider reader would report for a ground-truth take, drawn from an error model whose
// parameters are measured on full-fidelity runs (EstimateErrorModel below; docs/study.md,
// "Fidelity", says how the defaults were measured, and a test checks the fast mode against the
// full one). Section "error_model".
//
// Pose error of frame t: tracked_t = truth_t * proxy_T_error_t, proxy_T_error_t =
// (Exp(r_t), e_t) with r_t (rotation vector [rad]) and e_t (translation [m]) in the proxy frame,
// each of the six components an independent sum of two stationary AR(1) processes, a slow drift
// holding the share w of the variance and a fast jitter holding the rest:
//   x_t = s_t + f_t,  s_{t+1} = ρ_s s_t + sqrt(1 − ρ_s²) sqrt(w) σ n_t,
//                     f_{t+1} = ρ_f f_t + sqrt(1 − ρ_f²) sqrt(1 − w) σ m_t,  n_t, m_t ~ N(0, 1),
// started stationary, so that Var x_t = σ² and Corr(x_t, x_{t+k}) = w ρ_s^k + (1 − w) ρ_f^k. (The
// tracker's error is not one AR(1): on the full-fidelity study its autocorrelation falls from
// 0.5 at lag 1 to 0.37 at lag 2 and is still 0.23 at lag 8; docs/study.md, "The core's two time
// scales and flips through their losses".) With w = 0 it is the single AR(1) of earlier versions,
// x_{t+1} = ρ_f x_t + ..., with the same draws. On top of that, three kinds of episode, drawn
// in this order on the frames the earlier kinds left:
//   flips   the tracker holds the proxy's near-symmetric twin: the pose turned by flip_rotation
//           about the table's vertical and moved by flip_translation in a horizontal direction
//           (both fixed per episode; the Soldier seen side-on, tracked the wrong way round). The
//           tracker loses the proxy and finds the twin again in the course of one: each of its
//           frames is reported lost with probability flip_lost_share (on the full-fidelity study
//           192 of 244 runs of twin frames began after a lost frame, most of them inside one
//           longer episode; counted apart, each fragment would be a new twin with a new offset);
//   losses  the frames are reported lost (the last reported pose held; the run fills them in);
//   spikes  a short wrong fit: an error rotation vector and translation drawn per episode
//           (N(0, spike_rotation_sd²) and N(0, spike_translation_sd²) per axis, proxy frame),
//           added to the AR(1) error.
// The tracker fails where the view is ambiguous, so each kind's episodes depend on how the
// performed pose is seen: the frame's view condition c(t) (ViewCondition: the sector of the
// proxy's heading relative to the camera, or "lying" when it is tilted over) sets the hazards. An
// episode starts at a free frame t with probability rate(c(t)) and, after each of its frames u,
// ends with probability 1 / mean_frames(c(u)) (a two-state Markov chain per kind; with one
// condition the lengths are geometric with mean mean_frames, P(k) = (1 − 1/L)^(k−1) / L); it also
// ends at a frame an earlier kind took.
//
// Slider reading: read_t = clamp(truth_t + bias + s_t, −5, 5), s_t an AR(1) process like the
// above (sd slider_sd, lag-one correlation slider_correlation); a frame is not found with
// probability slider_miss_share, and then the last found value is held (the first found value
// before any is found).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/annotation.h"
#include "core/trajectory.h"
#include "pipeline/tracking_frames.h"
#include "track/proxy_tracker.h"

namespace mmh::pipeline {

// The episode hazards of one view condition (see the top of the file): episodes per free frame and
// mean length [frames] of losses, flips and spikes.
struct EpisodeRates {
  double loss_rate = 0.0;
  double loss_mean_frames = 1.0;
  double flip_rate = 0.0;
  double flip_mean_frames = 1.0;
  double spike_rate = 0.0;
  double spike_mean_frames = 1.0;

  template <class V>
  void VisitFields(V& v) {
    v("loss_rate", loss_rate);
    v("loss_mean_frames", loss_mean_frames);
    v("flip_rate", flip_rate);
    v("flip_mean_frames", flip_mean_frames);
    v("spike_rate", spike_rate);
    v("spike_mean_frames", spike_mean_frames);
  }
  void Validate(const std::string& prefix) const;
};

// View conditions: kHeadingSectors sectors of the proxy's heading relative to the camera (sector k:
// φ in [k·30°, (k+1)·30°), φ the angle in the table plane from the direction proxy → camera to the
// proxy's x axis, counter-clockwise seen from above; 0: facing the camera, 180°: facing away), and
// kLying (the proxy's z axis more than lying_tilt_deg from the table's vertical, where the heading
// says little).
inline constexpr int kHeadingSectors = 12;
inline constexpr int kLying = kHeadingSectors;
inline constexpr int kViewConditions = kHeadingSectors + 1;
// "heading_000", "heading_030", ..., "heading_330", "lying".
const char* ViewConditionName(int condition);

// The hazards per view condition (section "error_model.view").
struct ViewRates {
  std::array<EpisodeRates, kViewConditions> condition;

  template <class V>
  void VisitFields(V& v) {
    for (int c = 0; c < kViewConditions; ++c) v(ViewConditionName(c), condition[c]);
  }
  // The same hazards in every condition.
  static ViewRates Uniform(const EpisodeRates& rates);
};

// The measured defaults: pipeline/error_model.inc, written by a full-fidelity study
// (`mmh study ... --out DIR` writes DIR/error_model.inc; docs/study.md, "Fidelity", says how).
namespace measured {
#include "pipeline/error_model.inc"
}  // namespace measured

struct ErrorModelOptions {
  // Every default is measured (EstimateErrorModel) on the full-fidelity study of
  // configs/study_soldier.json (pipeline/error_model.inc says on what: takes, frames, commit).
  // Pose errors (see above), per axis in the proxy frame, over the frames within the tracker's
  // success criterion.
  double translation_sd = measured::kTranslationSd;  // σ_e [m]
  double rotation_sd = measured::kRotationSd;        // σ_r [rad]
  double correlation = measured::kCorrelation;       // ρ_f, the jitter's lag one, in [0, 1)
  double slow_share = measured::kSlowShare;          // w, the drift's share of σ², in [0, 1]
  double slow_correlation = measured::kSlowCorrelation;  // ρ_s, the drift's lag one, in [0, 1)
  // Flips (see above): rotation [rad] and translation [m] of the twin.
  double flip_rotation = measured::kFlipRotation;
  double flip_translation = measured::kFlipTranslation;
  // The share of a flip's frames reported lost, in [0, 1).
  double flip_lost_share = measured::kFlipLostShare;
  // Spikes (see above): per-axis sizes [rad], [m].
  double spike_rotation_sd = measured::kSpikeRotationSd;
  double spike_translation_sd = measured::kSpikeTranslationSd;
  // Where the proxy counts as lying (view condition kLying) [deg of its z axis from vertical].
  double lying_tilt_deg = 45.0;
  // Episode hazards per view condition.
  ViewRates view = measured::kView;
  // Slider reading: AR(1) noise [slider units] with its lag-one correlation, a bias, and the share
  // of frames in which the block is not found.
  double slider_sd = measured::kSliderSd;
  double slider_correlation = measured::kSliderCorrelation;
  double slider_bias = measured::kSliderBias;
  double slider_miss_share = measured::kSliderMissShare;

  template <class V>
  void VisitFields(V& v) {
    v("translation_sd", translation_sd);
    v("rotation_sd", rotation_sd);
    v("correlation", correlation);
    v("slow_share", slow_share);
    v("slow_correlation", slow_correlation);
    v("flip_rotation", flip_rotation);
    v("flip_translation", flip_translation);
    v("flip_lost_share", flip_lost_share);
    v("spike_rotation_sd", spike_rotation_sd);
    v("spike_translation_sd", spike_translation_sd);
    v("lying_tilt_deg", lying_tilt_deg);
    v("view", view);
    v("slider_sd", slider_sd);
    v("slider_correlation", slider_correlation);
    v("slider_bias", slider_bias);
    v("slider_miss_share", slider_miss_share);
  }
  void Validate(const std::string& prefix) const;
};

// The view condition of a performed pose (table_T_proxy) seen from a camera at
// `table_camera_position` (the camera's centre in the table frame).
int ViewCondition(const Rigid3& table_T_proxy, const Eigen::Vector3d& table_camera_position,
                  double lying_tilt_deg);
// The same from the pose's heading and tilt (ProxyHeadingDeg, ProxyTiltDeg).
int ViewConditionOf(double heading_deg, double tilt_deg, double lying_tilt_deg);

struct SimulatedTracking {
  Trajectory tracked;  // table_T_proxy, #frames (lost frames: the last reported pose held)
  std::vector<track::TrackStatus> status;  // #frames
};

// What the tracker reports for `truth` (table_T_proxy) seen from a camera at
// `table_camera_position` (table frame). Deterministic in `seed`.
SimulatedTracking SimulateTracking(const Trajectory& truth, const ErrorModelOptions& options,
                                   std::uint64_t seed,
                                   const Eigen::Vector3d& table_camera_position);

struct SimulatedReading {
  Annotation read;          // #frames, in [-5, 5], the last value held where not found
  std::vector<bool> found;  // #frames
};

// What the slider reader reports for the block's true values. Deterministic in `seed`.
SimulatedReading SimulateSliderReading(const Annotation& truth, const ErrorModelOptions& options,
                                       std::uint64_t seed);

// ---- Measuring the model on full-fidelity runs -------------------------------------------------

// The lags of the core's autocorrelation that the fit matches (1 .. kCoreLags frames).
inline constexpr int kCoreLags = 8;

struct ErrorModelEstimate {
  ErrorModelOptions options;  // the fitted model (fields without data keep `prior`'s values)
  // The moments as measured, before the correction by simulation (see EstimateErrorModel).
  ErrorModelOptions moments;
  // The correction: the fitted core's own excursion starts per frame at risk, the share of the
  // fitted spike episodes that the moments see, and the iterations it took.
  double core_excursion_rate = 0.0;
  // The inliers' autocorrelation at lags 1 .. kCoreLags as measured (pooled over the six
  // components, each type scaled by its variance; pairs of inlier frames k apart in one take).
  std::array<double, kCoreLags> core_autocorrelation{};
  double spike_visibility = 1.0;
  int simulation_iterations = 0;
  // Whether the correction was applied: not with fewer than 100 spike episodes, nor where the
  // fitted model does not give back the measured sizes within 5 % (then `options` holds the
  // moments, as `moments` does).
  bool corrected = false;
  std::int64_t frames = 0;    // tracked frames observed
  std::array<std::int64_t, kViewConditions> condition_frames{};  // of them, per view condition
  std::int64_t inlier_frames = 0;
  std::int64_t flip_frames = 0;       // frames in flip episodes (twin or lost)
  std::int64_t flip_lost_frames = 0;  // of them, lost
  std::int64_t spike_frames = 0;
  std::int64_t lost_frames = 0;       // lost frames outside flip episodes
  int flip_episodes = 0;
  int spike_episodes = 0;
  int loss_episodes = 0;
  std::int64_t slider_frames = 0;
  std::int64_t slider_missed = 0;
  double slider_rmse = 0.0;

  nlohmann::json ToJson() const;
  // pipeline/error_model.inc with these options as the measured defaults; `origin` is a comment
  // saying where they were measured (e.g. the study's config and commit).
  std::string DefaultsSource(const std::string& origin) const;
};

// Fits the model by moments. Frames within gross_threshold_deg and gross_threshold_m (the
// tracker's success criterion) are inliers: σ is the per-axis RMS, and w, ρ_s and ρ_f those whose
// autocorrelation w ρ_s^k + (1 − w) ρ_f^k is nearest (least squares, ρ on a grid of 0.001) to the
// inliers' pooled autocorrelation at lags k = 1 .. kCoreLags (pairs of inlier frames k apart in a
// take). Frames beyond it with a rotation error above 90° are twin frames, the others spikes. A
// flip episode is a run of twin and lost frames with at least one twin frame, flip_lost_share its
// lost frames' share; loss episodes are runs of lost frames outside them, spike episodes runs of
// spike frames: rate = episodes / frames at risk (the frames not in an episode of that kind or an
// earlier one), mean = frames / episodes; flip_rotation and flip_translation are the mean error
// angle and distance over twin frames, the spike sizes the per-axis RMS over spike frames. Per view condition (ViewCondition of the true pose, with prior.lying_tilt_deg): the start
// rate = episodes starting in it / its frames free at the time (not in an episode of that kind or
// an earlier one), the mean length = its episode frames / the episodes ending after one of them
// (the Markov chain's maximum-likelihood hazards); a condition without frames keeps `prior`'s. The
// slider's bias, sd and lag-one correlation over found frames, miss share = missed / frames.
//
// These moments (`moments`) are biased wherever the thresholds cut the model's own processes: the
// core noise goes past them by itself (with σ = 0.026 rad on about 1 % of frames), which they
// count as spikes; spikes smaller than the thresholds count as core noise and are missed as
// spikes; the core's RMS is taken over frames cut at the thresholds. So the core (σ, w, ρ_s, ρ_f),
// the spikes' sizes and their pooled rate and mean length are corrected by simulation (indirect
// inference): they are the model whose simulated frames (the core and spikes of SimulateTracking,
// one view condition, from fixed seeds) give the measured pooled moments (for the core's time
// scales: its autocorrelation at lags 1 .. kCoreLags). The rate per view
// condition is then (measured rate − the core's own excursion rate) / the spikes' visibility
// (the share of spike episodes the moments see), the length the measured one times the pooled
// correction. Losses, flips and the slider keep their moments. With fewer than 100 spike episodes,
// or where the fitted model does not give back the measured sizes, the moments stay
// (`corrected` false).
ErrorModelEstimate EstimateErrorModel(const std::vector<TrackingObservation>& tracking,
                                      const std::vector<ReadingObservation>& readings,
                                      const ErrorModelOptions& prior = {},
                                      double gross_threshold_deg = 5.0,
                                      double gross_threshold_m = 0.01);
// The same fit from the per-frame table (pipeline/tracking_frames.h; a study's
// tracking_errors.csv): the tracking of every take, the slider of the takes that have one. Gives
// the bytes of the fit above on the observations the table was measured from.
ErrorModelEstimate EstimateErrorModel(const std::vector<TakeFrames>& takes,
                                      const ErrorModelOptions& prior = {},
                                      double gross_threshold_deg = 5.0,
                                      double gross_threshold_m = 0.01);

}  // namespace mmh::pipeline
