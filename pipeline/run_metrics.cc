#include "pipeline/run_metrics.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>

#include "core/cross_correlation.h"
#include "core/error.h"
#include "metrics/annotation_metrics.h"
#include "metrics/motion_metrics.h"
#include "metrics/tracking_metrics.h"
#include "metrics/trajectory_error.h"
#include "pipeline/animator_run.h"
#include "sim/render_session.h"

namespace mmh::pipeline {

namespace {

constexpr double kDegrees = 180.0 / 3.14159265358979323846;

double Mean(std::span<const double> values) {
  if (values.empty()) return 0.0;
  double sum = 0.0;
  for (double v : values) sum += v;
  return sum / values.size();
}

// Rotation and translation errors, ADD/ADD-S, success and losses of one take in the depth
// camera's frame (what the tracker measures: camera_T_proxy against the rendered ground truth),
// and evo's APE/RPE in the table frame (what the compositor gets: the tracker's estimate of the
// table frame against the true one, so the calibration's error is included).
TakeTrackingMetrics TrackingMetrics(const TakeRun& take, const Eigen::Matrix<double, -1, 3>& points,
                                    const metrics::PoseErrorOptions& options,
                                    std::vector<double>* rotation_errors,
                                    std::vector<double>* translation_errors) {
  const int frames = static_cast<int>(take.truth.poses.size());
  TakeTrackingMetrics m;
  std::vector<std::optional<Rigid3>> estimates(frames);
  for (int i = 0; i < frames; ++i) {
    switch (take.status[i]) {
      case track::TrackStatus::kTracked:
        ++m.tracked;
        break;
      case track::TrackStatus::kPredicted:
        ++m.predicted;
        break;
      case track::TrackStatus::kLost:
        ++m.lost;
        break;
    }
    if (take.status[i] != track::TrackStatus::kLost) {
      estimates[i] = take.estimated_camera_T_table * take.tracked.poses[i];
    }
  }
  std::vector<Rigid3> camera_truth(frames);
  for (int i = 0; i < frames; ++i) camera_truth[i] = take.camera_T_table * take.truth.poses[i];
  const std::vector<metrics::FramePoseError> errors =
      metrics::ComputePoseErrors(estimates, camera_truth, points, options);
  m.summary = metrics::SummarizeTracking(errors, metrics::Diameter(points), options);
  std::vector<double> rotation, translation;
  for (const metrics::FramePoseError& e : errors) {
    if (!e.has_estimate) continue;
    rotation.push_back(e.rotation_deg);
    translation.push_back(e.translation);
  }
  m.rotation_deg = metrics::Statistics(rotation);
  m.translation_m = metrics::Statistics(translation);
  int recoveries = 0;
  double recovery_sum = 0.0;
  for (const metrics::FailureRun& run : m.summary.failures) {
    if (run.recovered) ++recoveries, recovery_sum += run.length;
  }
  m.losses = static_cast<int>(m.summary.failures.size());
  m.mean_recovery_frames = recoveries > 0 ? recovery_sum / recoveries : 0.0;
  // The table frame's error: the estimated camera_T_table against the true one.
  const Rigid3 table_error = take.camera_T_table.Inverse() * take.estimated_camera_T_table;
  m.table_frame_rotation_deg =
      RotationAngle(Eigen::Quaterniond::Identity(), table_error.rotation) * kDegrees;
  m.table_frame_translation_m = table_error.translation.norm();
  // evo over the frames with a pose (the filled gaps are the compositor's, not the tracker's).
  std::vector<Rigid3> estimated, reference;
  for (int i = 0; i < frames; ++i) {
    if (take.status[i] == track::TrackStatus::kLost) continue;
    estimated.push_back(take.tracked.poses[i]);
    reference.push_back(take.truth.poses[i]);
  }
  m.ape_translation_m =
      metrics::Statistics(metrics::AbsoluteTranslationErrors(estimated, reference));
  // RPE over consecutive frames of the whole take, gaps filled as the compositor gets them.
  const metrics::RelativeErrors rpe =
      metrics::RelativePoseErrors(take.tracked.poses, take.truth.poses, 1);
  m.rpe_translation_m = metrics::Statistics(rpe.translation);
  m.rpe_rotation_deg = metrics::Statistics(rpe.rotation_deg);
  rotation_errors->insert(rotation_errors->end(), rotation.begin(), rotation.end());
  translation_errors->insert(translation_errors->end(), translation.begin(), translation.end());
  return m;
}

TakeAnnotationMetrics AnnotationMetrics(const TakeRun& take, double frame_rate,
                                        double reaction_time) {
  TakeAnnotationMetrics m;
  m.errors = metrics::CompareAnnotations(take.truth_annotation.values, take.read_annotation.values);
  const auto found = std::count(take.slider_found.begin(), take.slider_found.end(), true);
  m.found_share =
      take.slider_found.empty() ? 0.0 : static_cast<double>(found) / take.slider_found.size();
  // The annotator's lag behind their own opinion, as the read values show it, against the
  // compositor's reaction shift (DESIGN.md: 0.3 s).
  const int frames = static_cast<int>(take.read_annotation.values.size());
  const std::span<const double> judgement(take.annotation.judgement.data(), frames);
  const int max_lag = std::min(60, frames - 3);
  if (max_lag >= 1) {
    m.reaction_lag_s =
        CrossCorrelationLag(judgement, take.read_annotation.values, max_lag) / frame_rate;
    m.true_reaction_lag_s =
        CrossCorrelationLag(judgement, take.truth_annotation.values, max_lag) / frame_rate;
  }
  m.reaction_shift_s = reaction_time;
  double delay = 0.0;
  for (int i = 0; i < frames; ++i) delay += take.annotation.delay[i];
  m.mean_true_delay_s = frames > 0 ? delay / frames : 0.0;
  return m;
}

// The montage's own metrics: costs, constraint, annotation use, segments, seams, quality.
MontageMetrics ComputeMontageMetrics(const montage::Montage& montage,
                                     const std::vector<double>& quality,
                                     const std::vector<Trajectory>& takes,
                                     const std::vector<std::vector<double>>& take_quality,
                                     double frame_rate, int blend_window) {
  MontageMetrics m;
  m.compose = montage.summary;
  m.segments = static_cast<int>(montage.segments.size());

  // Liked frames used: of the reference frames where some take is liked (warped annotation > 0),
  // the share whose chosen take is liked. Disliked frames avoided: of the reference frames where
  // some take is disliked (< 0) and some is not, the share whose chosen take is not disliked.
  const int n = static_cast<int>(montage.labels.size());
  int liked_used = 0, disliked_avoided = 0;
  for (int t = 0; t < n; ++t) {
    bool any_liked = false, any_disliked = false, any_not_disliked = false;
    for (const std::vector<double>& a : montage.warped_annotations) {
      any_liked |= a[t] > 0;
      any_disliked |= a[t] < 0;
      any_not_disliked |= a[t] >= 0;
    }
    const double chosen = montage.warped_annotations[montage.labels[t]][t];
    if (any_liked) ++m.liked_frames, liked_used += chosen > 0;
    if (any_disliked && any_not_disliked) ++m.disliked_frames, disliked_avoided += chosen >= 0;
  }
  m.liked_used_share =
      m.liked_frames > 0 ? static_cast<double>(liked_used) / m.liked_frames : 1.0;
  m.disliked_avoided_share =
      m.disliked_frames > 0 ? static_cast<double>(disliked_avoided) / m.disliked_frames : 1.0;

  // Seams: the largest change within the blend window around each transition, against the
  // takes' own frame-to-frame changes (their 95th percentile and maximum).
  const metrics::MotionChanges changes =
      metrics::ComputeMotionChanges(montage.trajectory.poses, frame_rate);
  std::vector<double> own_position, own_velocity, own_angular;
  for (const Trajectory& take : takes) {
    const metrics::MotionChanges c = metrics::ComputeMotionChanges(take.poses, frame_rate);
    own_position.insert(own_position.end(), c.position.begin() + 1, c.position.end());
    own_velocity.insert(own_velocity.end(), c.velocity.begin() + 1, c.velocity.end() - 1);
    own_angular.insert(own_angular.end(), c.angular_velocity.begin() + 1,
                       c.angular_velocity.end() - 1);
  }
  const int radius = blend_window / 2 + 1;
  std::vector<double> seam_position, seam_velocity, seam_angular;
  for (size_t k = 1; k < montage.segments.size(); ++k) {
    const int frame = montage.segments[k].montage_first;
    seam_position.push_back(metrics::WindowMax(changes.position, frame, radius));
    seam_velocity.push_back(metrics::WindowMax(changes.velocity, frame, radius));
    seam_angular.push_back(metrics::WindowMax(changes.angular_velocity, frame, radius));
    m.seam_list.push_back({frame, montage.segments[k - 1].take, montage.segments[k].take,
                           seam_position.back(), seam_velocity.back(), seam_angular.back()});
  }
  auto max_of = [](const std::vector<double>& v) {
    return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end());
  };
  m.seam_count = static_cast<int>(seam_position.size());
  auto summarize = [&](const std::vector<double>& seam, const std::vector<double>& own) {
    const double own_p95 = metrics::Quantile(own, 0.95);
    return SeamChangeSummary{max_of(seam),
                             Mean(seam),
                             metrics::Quantile(own, 0.5),
                             own_p95,
                             max_of(own),
                             own_p95 > 0 ? max_of(seam) / own_p95 : 0.0};
  };
  m.position_jump_m = summarize(seam_position, own_position);
  m.velocity_jump_m_per_s = summarize(seam_velocity, own_velocity);
  m.angular_velocity_jump_deg_per_s = summarize(seam_angular, own_angular);

  // Latent quality (carried from the takes' frames) against each take's.
  m.mean_quality = Mean(quality);
  for (const std::vector<double>& q : take_quality) m.take_mean_quality.push_back(Mean(q));
  m.quality_gain_over_best_take = Mean(quality) - max_of(m.take_mean_quality);
  m.quality_gain_over_mean_take = Mean(quality) - Mean(m.take_mean_quality);
  return m;
}

nlohmann::json ToJson(const TakeTrackingMetrics& m) {
  nlohmann::json j = metrics::ToJson(m.summary);
  j["rotation_deg"] = metrics::ToJson(m.rotation_deg);
  j["translation_m"] = metrics::ToJson(m.translation_m);
  j["tracked"] = m.tracked;
  j["predicted"] = m.predicted;
  j["lost"] = m.lost;
  j["losses"] = m.losses;
  j["mean_recovery_frames"] = m.mean_recovery_frames;
  j["table_frame_rotation_deg"] = m.table_frame_rotation_deg;
  j["table_frame_translation_m"] = m.table_frame_translation_m;
  j["ape_translation_m"] = metrics::ToJson(m.ape_translation_m);
  j["rpe_translation_m"] = metrics::ToJson(m.rpe_translation_m);
  j["rpe_rotation_deg"] = metrics::ToJson(m.rpe_rotation_deg);
  return j;
}

nlohmann::json ToJson(const TakeAnnotationMetrics& m) {
  nlohmann::json j = metrics::ToJson(m.errors);
  j["found_share"] = m.found_share;
  if (m.reaction_lag_s) j["reaction_lag_s"] = *m.reaction_lag_s;
  if (m.true_reaction_lag_s) j["true_reaction_lag_s"] = *m.true_reaction_lag_s;
  j["reaction_shift_s"] = m.reaction_shift_s;
  j["mean_true_delay_s"] = m.mean_true_delay_s;
  return j;
}

nlohmann::json ToJson(const SeamChangeSummary& s) {
  return {{"seam_max", s.seam_max},
          {"seam_mean", s.seam_mean},
          {"takes_median", s.takes_median},
          {"takes_p95", s.takes_p95},
          {"takes_max", s.takes_max},
          {"seam_max_over_takes_p95", s.seam_max_over_takes_p95}};
}

nlohmann::json ToJson(const MontageMetrics& m) {
  // The compositor's summary (montage/compose.h) without its timings, then what the montage
  // achieved.
  nlohmann::json j = montage::SummaryToJson(m.compose, {});
  j.erase("seconds");
  j["segments"] = m.segments;
  j["liked_frames"] = m.liked_frames;
  j["liked_used_share"] = m.liked_used_share;
  j["disliked_frames"] = m.disliked_frames;
  j["disliked_avoided_share"] = m.disliked_avoided_share;
  nlohmann::json seams = nlohmann::json::array();
  for (const SeamJump& s : m.seam_list) {
    seams.push_back({{"frame", s.frame},
                     {"from_take", s.from_take},
                     {"to_take", s.to_take},
                     {"position_jump_m", s.position_jump_m},
                     {"velocity_jump_m_per_s", s.velocity_jump_m_per_s},
                     {"angular_velocity_jump_deg_per_s", s.angular_velocity_jump_deg_per_s}});
  }
  j["seams"] = {{"count", m.seam_count},
                {"position_jump_m", ToJson(m.position_jump_m)},
                {"velocity_jump_m_per_s", ToJson(m.velocity_jump_m_per_s)},
                {"angular_velocity_jump_deg_per_s", ToJson(m.angular_velocity_jump_deg_per_s)}};
  j["seam_list"] = seams;
  j["mean_quality"] = m.mean_quality;
  j["take_mean_quality"] = m.take_mean_quality;
  j["quality_gain_over_best_take"] = m.quality_gain_over_best_take;
  j["quality_gain_over_mean_take"] = m.quality_gain_over_mean_take;
  return j;
}

}  // namespace

RunMetrics ComputeRunMetrics(const RunConfig& config, const AnimatorRun& run,
                             const TriangleMesh& proxy_model, const TriangleMesh* practice_model) {
  const double fps = config.people.performance.frame_rate;
  RunMetrics m;
  m.scenario.story = config.people.scenario.story;
  m.scenario.object = config.people.scenario.object;
  m.scenario.animator = run.participant.index;
  m.scenario.takes = static_cast<int>(run.takes.size());
  m.scenario.practice = config.run.practice;
  m.scenario.fidelity = EnumName(config.run.fidelity);
  // (Not rendered_frames: it counts the work of this process, 0 for takes that --resume loaded,
  // so it is in run.json's "seconds" with the timings; metrics.json is a function of the config.)

  // The proxy's metric points (ADD/ADD-S), from the model the sensor rendered.
  const auto points = metrics::MetricPoints(proxy_model);

  std::vector<double> rotation, translation, practice_rotation, practice_translation;
  std::vector<double> squared_slider;
  for (const TakeRun& take : run.takes) {
    TakeMetrics t;
    t.take = take.take;
    t.frames = static_cast<int>(take.truth.poses.size());
    t.skill = take.performed.skill;
    t.mean_quality = Mean(
        std::span<const double>(take.performed.quality.quality.data(), take.truth.poses.size()));
    t.flaws = static_cast<int>(take.performed.flaws.size());
    t.tracking = TrackingMetrics(take, points, config.metrics, &rotation, &translation);
    t.annotation = AnnotationMetrics(take, fps, config.montage.reaction_time);
    for (size_t i = 0; i < take.truth_annotation.values.size(); ++i) {
      const double d = take.read_annotation.values[i] - take.truth_annotation.values[i];
      squared_slider.push_back(d * d);
    }
    m.takes.push_back(std::move(t));
  }
  if (run.practice) {
    const auto practice_points = metrics::MetricPoints(*practice_model);
    m.practice = PracticeMetrics{
        run.practice->take, static_cast<int>(run.practice->truth.poses.size()),
        Mean(std::span<const double>(run.practice->performed.quality.quality.data(),
                                     run.practice->truth.poses.size())),
        TrackingMetrics(*run.practice, practice_points, config.metrics, &practice_rotation,
                        &practice_translation)};
  }

  // Pooled over the takes.
  int frames = 0, with_estimate = 0, successes = 0;
  for (const TakeMetrics& t : m.takes) {
    const int f = t.tracking.summary.frames;
    frames += f;
    with_estimate += t.tracking.summary.frames_with_estimate;
    successes += static_cast<int>(std::lround(t.tracking.summary.success_rate * f));
  }
  m.tracking = {frames, frames > 0 ? static_cast<double>(with_estimate) / frames : 0.0,
                frames > 0 ? static_cast<double>(successes) / frames : 0.0,
                metrics::Statistics(rotation), metrics::Statistics(translation)};
  double slider_sse = 0.0;
  for (double s : squared_slider) slider_sse += s;
  m.annotation = {static_cast<int>(squared_slider.size()),
                  squared_slider.empty() ? 0.0 : std::sqrt(slider_sse / squared_slider.size())};

  // The montages.
  std::vector<Trajectory> tracked, truth;
  std::vector<std::vector<double>> take_quality;
  for (const TakeRun& take : run.takes) {
    tracked.push_back(take.tracked);
    truth.push_back(take.truth);
    take_quality.push_back(
        std::vector<double>(take.performed.quality.quality.begin(),
                            take.performed.quality.quality.begin() + take.truth.poses.size()));
  }
  const int window = config.montage.blend.window;
  m.tracked =
      ComputeMontageMetrics(run.montage, run.montage_quality, tracked, take_quality, fps, window);
  m.truth = ComputeMontageMetrics(run.truth_montage, run.truth_montage_quality, truth,
                                  take_quality, fps, window);
  // The montage from tracked data against the one from the ground truth: both are on the first
  // take's (the reference's) timeline, so their labels compare frame by frame.
  const std::vector<int>& a = run.montage.labels;
  const std::vector<int>& b = run.truth_montage.labels;
  int same = 0;
  for (size_t t = 0; t < std::min(a.size(), b.size()); ++t) same += a[t] == b[t];
  m.tracked_vs_truth = {
      a.empty() ? 0.0 : static_cast<double>(same) / a.size(),
      static_cast<int>(run.montage.segments.size()) -
          static_cast<int>(run.truth_montage.segments.size()),
      run.montage.summary.montage_frames - run.truth_montage.summary.montage_frames,
      Mean(run.montage_quality) - Mean(run.truth_montage_quality)};
  return m;
}

nlohmann::json ToJson(const RunMetrics& m) {
  nlohmann::json j;
  j["scenario"] = {{"story", m.scenario.story},
                   {"object", m.scenario.object},
                   {"animator", m.scenario.animator},
                   {"takes", m.scenario.takes},
                   {"practice", m.scenario.practice},
                   {"fidelity", m.scenario.fidelity}};
  nlohmann::json takes = nlohmann::json::array();
  for (const TakeMetrics& t : m.takes) {
    takes.push_back({{"take", t.take},
                     {"frames", t.frames},
                     {"skill", t.skill},
                     {"mean_quality", t.mean_quality},
                     {"flaws", t.flaws},
                     {"tracking", ToJson(t.tracking)},
                     {"annotation", ToJson(t.annotation)}});
  }
  j["takes"] = takes;
  if (m.practice) {
    j["practice"] = {{"take", m.practice->take},
                     {"frames", m.practice->frames},
                     {"mean_quality", m.practice->mean_quality},
                     {"tracking", ToJson(m.practice->tracking)}};
  }
  j["tracking"] = {{"frames", m.tracking.frames},
                   {"estimated_share", m.tracking.estimated_share},
                   {"success_rate", m.tracking.success_rate},
                   {"rotation_deg", metrics::ToJson(m.tracking.rotation_deg)},
                   {"translation_m", metrics::ToJson(m.tracking.translation_m)}};
  j["annotation"] = {{"frames", m.annotation.frames}, {"rmse", m.annotation.rmse}};
  j["montage"] = {{"tracked", ToJson(m.tracked)},
                  {"truth", ToJson(m.truth)},
                  {"tracked_vs_truth",
                   {{"label_agreement", m.tracked_vs_truth.label_agreement},
                    {"segments_difference", m.tracked_vs_truth.segments_difference},
                    {"frames_difference", m.tracked_vs_truth.frames_difference},
                    {"mean_quality_difference", m.tracked_vs_truth.mean_quality_difference}}}};
  return j;
}

double RenderTrackFramesPerSecond(const AnimatorRun& run) {
  const double sessions = run.seconds.record + run.seconds.annotate;
  return sessions > 0 ? run.rendered_frames / sessions : 0.0;
}

nlohmann::json SecondsToJson(const AnimatorRun& run) {
  const StageSeconds& s = run.seconds;
  return {{"perform", s.perform},
          {"record", s.record},
          {"annotate", s.annotate},
          {"compose", s.compose},
          {"metrics", s.metrics},
          {"total", s.total},
          {"rendered_frames", run.rendered_frames},
          {"render_track_frames_per_second", RenderTrackFramesPerSecond(run)}};
}

std::string TimingsToCsv(const AnimatorRun& run) {
  const StageSeconds& s = run.seconds;
  int record_frames = 0, annotate_frames = 0;
  if (run.rendered_frames > 0) {
    for (const TakeRun& t : run.takes) {
      record_frames += static_cast<int>(t.status.size());
      annotate_frames += static_cast<int>(t.read_annotation.values.size());
    }
    if (run.practice) record_frames += static_cast<int>(run.practice->status.size());
  }
  auto row = [](const char* stage, double seconds, int frames) {
    return std::string(stage) + "," + FormatNumber(seconds) + "," + std::to_string(frames) + "," +
           FormatNumber(seconds > 0 && frames > 0 ? frames / seconds : 0.0) + "\n";
  };
  return "stage,seconds,frames,frames_per_second\n" + row("perform", s.perform, 0) +
         row("record", s.record, record_frames) + row("annotate", s.annotate, annotate_frames) +
         row("render_and_track", s.record + s.annotate, run.rendered_frames) +
         row("compose", s.compose, 0) + row("metrics", s.metrics, 0) +
         row("total", s.total, run.rendered_frames);
}

std::vector<std::pair<std::string, double>> FlattenMetrics(const nlohmann::json& metrics) {
  std::vector<std::pair<std::string, double>> out;
  std::function<void(const nlohmann::json&, const std::string&)> walk =
      [&](const nlohmann::json& j, const std::string& prefix) {
        if (j.is_object()) {
          for (const auto& [key, value] : j.items()) {
            walk(value, prefix.empty() ? key : prefix + "." + key);
          }
        } else if (j.is_array()) {
          for (size_t i = 0; i < j.size(); ++i) walk(j[i], prefix + "." + std::to_string(i));
        } else if (j.is_boolean()) {
          out.emplace_back(prefix, j.get<bool>() ? 1.0 : 0.0);
        } else if (j.is_number()) {
          out.emplace_back(prefix, j.get<double>());
        }
      };
  walk(metrics, "");
  return out;
}

}  // namespace mmh::pipeline
