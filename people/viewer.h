// The viewer model the study needs: how good an animation (a take or a montage) looks to a
// director. This is the harness's hypothesis (docs/people.md), every parameter in the config
// section "viewer":
//
//   appeal   A = mean_t q(t) − w_a · (artefacts per minute)
//   artefact at frame t: the smoothed motion's velocity changes in one frame by much more than
//            it does around that moment (a jump or jerk stands out from the motion's own rhythm
//            of steps and tremor); its size is the excess over the threshold, in thresholds,
//            capped per frame, for translation and rotation:
//              e(t) = min(c, max(0, |Δv(t)|/(k·ρ_v(t) + v_0) − 1))
//                   + min(c, max(0, |Δω(t)|/(k·ρ_ω(t) + ω_0) − 1))
//            where v and ω are the velocities of the trajectory after a centred moving average of
//            `smoothing` frames, Δ the change from one frame to the next, and ρ(t) the RMS of Δ
//            over ±`context` s around t leaving out t's own neighbourhood (±smoothing frames);
//   a viewer's utility  U = b_q·A_q − s·w_a·artefacts + ε, b_q and s per viewer (taste), ε per
//            viewing, N(0, σ²); a comparison prefers the animation of higher utility.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/trajectory.h"

namespace mmh::people {

struct ViewerOptions {
  // w_a and σ are calibrated to the paper's study (docs/calibration.md).
  double artefact_weight = 0.0285;       // w_a: appeal lost per artefact unit per minute
  double velocity_threshold = 0.03;      // v_0 [m/s] change of the smoothed velocity in one frame
  double angular_threshold = 0.6;        // ω_0 [rad/s] change of the smoothed angular velocity
  double contrast = 3.0;                 // k: how far above the local rhythm a change stands out
  double context = 1.0;                  // [s] half window of the local rhythm ρ
  double artefact_cap = 3.0;             // c: one frame's artefact counts at most this much
  int smoothing = 5;                     // frames of the centred moving average (odd)
  double quality_weight_sd = 0.15;       // spread of b_q (mean 1) between viewers
  double artefact_sensitivity_sd = 0.3;  // log-sd of s (median 1) between viewers
  double judgement_noise = 0.179;        // σ per viewing

  template <class V>
  void VisitFields(V& v) {
    v("artefact_weight", artefact_weight);
    v("velocity_threshold", velocity_threshold);
    v("angular_threshold", angular_threshold);
    v("contrast", contrast);
    v("context", context);
    v("artefact_cap", artefact_cap);
    v("smoothing", smoothing);
    v("quality_weight_sd", quality_weight_sd);
    v("artefact_sensitivity_sd", artefact_sensitivity_sd);
    v("judgement_noise", judgement_noise);
  }
  void Validate(const std::string& prefix) const;
};

// What the animation offers any viewer.
struct Appeal {
  double mean_quality = 0.0;  // mean latent quality over the frames
  double artefacts = 0.0;     // Σ e(t)
  double artefacts_per_minute = 0.0;
  int artefact_frames = 0;  // frames with e(t) > 0
  double appeal = 0.0;      // A
};

// `animation`: #frames poses (table or camera frame, timestamps at the frame rate);
// `quality`: #frames latent quality in [0, 1].
Appeal Appraise(const Trajectory& animation, std::span<const double> quality,
                const ViewerOptions& options);

// Per-frame artefact sizes e(t) (#frames), for plots and metrics.
std::vector<double> ArtefactTrace(const Trajectory& animation, const ViewerOptions& options);

// One viewer (a scorer or an animator looking at animations).
struct Viewer {
  double quality_weight = 1.0;        // b_q
  double artefact_sensitivity = 1.0;  // s
};
// Draws viewer `index` of a population; deterministic in (seed, index).
Viewer DrawViewer(const ViewerOptions& options, std::uint64_t seed, int index);

// The viewer's utility of an animation in one viewing; `viewing` keys the noise (e.g. a
// comparison's index), so that repeated calls with the same arguments agree.
double Utility(const Appeal& appeal, const Viewer& viewer, const ViewerOptions& options,
               std::uint64_t seed, std::uint64_t viewing);

// Latent quality of a composite per frame: frame t comes from take take_of_frame[t] at its frame
// source_frame[t] (both #frames), and carries that frame's quality.
std::vector<double> CompositeQuality(std::span<const std::vector<double>> take_quality,
                                     std::span<const int> take_of_frame,
                                     std::span<const int> source_frame);

}  // namespace mmh::people
