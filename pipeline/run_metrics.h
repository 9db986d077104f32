// The metrics of one animator's run (metrics.json), typed: tracking against the ground truth
// (errors, ADD/ADD-S, success, losses and recovery, evo's APE/RPE), annotation reading (RMSE, lag,
// clipping), and the montage (costs, the Segment Length Constraint's cost, liked frames used and
// disliked frames avoided, segments, seam jumps against the takes' own, latent quality against the
// takes', and how much the montage from tracked data differs from the one from the ground truth).
// JSON only at the edge: ToJson writes metrics.json, and `mmh regress` and metrics.csv read its
// flattened keys. docs/pipeline.md defines every entry.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/triangle_mesh.h"
#include "metrics/annotation_metrics.h"
#include "metrics/tracking_metrics.h"
#include "metrics/trajectory_error.h"
#include "montage/compose.h"

namespace mmh::pipeline {

struct RunConfig;
struct AnimatorRun;

// One take's tracking: in the depth camera's frame (what the tracker measures) and, for evo's
// APE/RPE, in the table frame (what the compositor gets, the table's calibration error included).
struct TakeTrackingMetrics {
  metrics::TrackingSummary summary;        // success, ADD/ADD-S, failures over all frames
  metrics::ErrorStatistics rotation_deg;   // over the frames with an estimate
  metrics::ErrorStatistics translation_m;  // over the frames with an estimate
  int tracked = 0;                         // frames by track::TrackStatus
  int predicted = 0;
  int lost = 0;
  int losses = 0;                     // failure runs (summary.failures)
  double mean_recovery_frames = 0.0;  // mean length of the recovered failure runs
  // The estimated camera_T_table against the true one.
  double table_frame_rotation_deg = 0.0;
  double table_frame_translation_m = 0.0;
  metrics::ErrorStatistics ape_translation_m;  // frames with a pose (gaps are not the tracker's)
  metrics::ErrorStatistics rpe_translation_m;  // consecutive frames, gaps filled
  metrics::ErrorStatistics rpe_rotation_deg;
};

// One take's annotation as the slider reader read it, and the annotator's timing.
struct TakeAnnotationMetrics {
  metrics::AnnotationErrors errors;  // read against the slider block's true values
  double found_share = 0.0;          // frames where the reader found the block
  // Lag of the read (and the true) slider values behind the annotator's judgement [s], by
  // cross-correlation; absent for takes too short to measure it.
  std::optional<double> reaction_lag_s;
  std::optional<double> true_reaction_lag_s;
  double reaction_shift_s = 0.0;   // the compositor's reaction shift (montage.reaction_time)
  double mean_true_delay_s = 0.0;  // the simulated annotator's mean delay
};

struct TakeMetrics {
  int take = 0;
  int frames = 0;
  double skill = 0.0;
  double mean_quality = 0.0;  // latent quality of the performed take
  int flaws = 0;
  TakeTrackingMetrics tracking;
  TakeAnnotationMetrics annotation;
};

struct PracticeMetrics {
  int take = 0;
  int frames = 0;
  double mean_quality = 0.0;
  TakeTrackingMetrics tracking;
};

// A transition of the montage: the largest frame-to-frame change within the blend window.
struct SeamJump {
  int frame = 0;  // montage frame of the segment's first frame
  int from_take = 0;
  int to_take = 0;
  double position_jump_m = 0.0;
  double velocity_jump_m_per_s = 0.0;
  double angular_velocity_jump_deg_per_s = 0.0;
};

// One kind of change at the seams against the takes' own frame-to-frame changes.
struct SeamChangeSummary {
  double seam_max = 0.0;
  double seam_mean = 0.0;
  double takes_median = 0.0;
  double takes_p95 = 0.0;
  double takes_max = 0.0;
  double seam_max_over_takes_p95 = 0.0;  // 0 when the takes' p95 is 0
};

struct MontageMetrics {
  montage::ComposeSummary compose;  // the compositor's summary (its timings are not metrics)
  int segments = 0;
  int liked_frames = 0;  // reference frames where some take is liked (warped annotation > 0)
  double liked_used_share = 1.0;  // of those, the share whose chosen take is liked
  int disliked_frames = 0;  // reference frames where some take is disliked and some is not
  double disliked_avoided_share = 1.0;  // of those, the share whose chosen take is not disliked
  int seam_count = 0;
  SeamChangeSummary position_jump_m;
  SeamChangeSummary velocity_jump_m_per_s;
  SeamChangeSummary angular_velocity_jump_deg_per_s;
  std::vector<SeamJump> seam_list;
  double mean_quality = 0.0;  // latent quality carried from the takes' frames
  std::vector<double> take_mean_quality;
  double quality_gain_over_best_take = 0.0;
  double quality_gain_over_mean_take = 0.0;
};

// The montage from tracked data against the one from the ground truth (both on the reference
// take's timeline, so labels compare frame by frame).
struct MontageComparison {
  double label_agreement = 0.0;
  int segments_difference = 0;
  int frames_difference = 0;
  double mean_quality_difference = 0.0;
};

struct RunMetrics {
  struct Scenario {
    std::string story;
    int object = 0;  // the story's object (scenario.object)
    int animator = 0;
    int takes = 0;
    std::string practice;
    std::string fidelity;
  } scenario;
  std::vector<TakeMetrics> takes;
  std::optional<PracticeMetrics> practice;
  // Pooled over the takes.
  struct Tracking {
    int frames = 0;
    double estimated_share = 0.0;
    double success_rate = 0.0;
    metrics::ErrorStatistics rotation_deg;
    metrics::ErrorStatistics translation_m;
  } tracking;
  struct Annotation {
    int frames = 0;
    double rmse = 0.0;
  } annotation;
  MontageMetrics tracked;  // metrics.json "montage.tracked"
  MontageMetrics truth;    // metrics.json "montage.truth"
  MontageComparison tracked_vs_truth;
};

// `proxy_model` and `practice_model` (when the run has a practice take) are the models the
// sessions rendered (for ADD/ADD-S).
RunMetrics ComputeRunMetrics(const RunConfig& config, const AnimatorRun& run,
                             const TriangleMesh& proxy_model, const TriangleMesh* practice_model);

// metrics.json.
nlohmann::json ToJson(const RunMetrics& metrics);

// Time per stage [s] and frames per second (metrics.json "seconds").
nlohmann::json SecondsToJson(const AnimatorRun& run);
// render_track_frames_per_second of SecondsToJson.
double RenderTrackFramesPerSecond(const AnimatorRun& run);

// The same as a tidy CSV: stage,seconds,frames,frames_per_second (frames: those the stage
// rendered and tracked or read).
std::string TimingsToCsv(const AnimatorRun& run);

// metrics.json flattened to "a.b.c" keys (arrays indexed: "takes.0.tracking.success_rate"), in
// key order; the tidy metrics.csv and `mmh regress` read it.
std::vector<std::pair<std::string, double>> FlattenMetrics(const nlohmann::json& metrics);

}  // namespace mmh::pipeline
