#include "pipeline/run_metrics.h"

#include <algorithm>
#include <cmath>
#include <functional>
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
nlohmann::json TrackingMetrics(const TakeRun& take, const Eigen::Matrix<double, -1, 3>& points,
                               const metrics::PoseErrorOptions& options,
                               std::vector<double>* rotation_errors,
                               std::vector<double>* translation_errors) {
  const int frames = static_cast<int>(take.truth.poses.size());
  std::vector<std::optional<Rigid3>> estimates(frames);
  int tracked = 0, predicted = 0, lost = 0;
  for (int i = 0; i < frames; ++i) {
    switch (take.status[i]) {
      case track::TrackStatus::kTracked:
        ++tracked;
        break;
      case track::TrackStatus::kPredicted:
        ++predicted;
        break;
      case track::TrackStatus::kLost:
        ++lost;
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
  const metrics::TrackingSummary summary =
      metrics::SummarizeTracking(errors, metrics::Diameter(points), options);
  nlohmann::json j = metrics::ToJson(summary);
  std::vector<double> rotation, translation;
  for (const metrics::FramePoseError& e : errors) {
    if (!e.has_estimate) continue;
    rotation.push_back(e.rotation_deg);
    translation.push_back(e.translation);
  }
  j["rotation_deg"] = metrics::ToJson(metrics::Statistics(rotation));
  j["translation_m"] = metrics::ToJson(metrics::Statistics(translation));
  j["tracked"] = tracked;
  j["predicted"] = predicted;
  j["lost"] = lost;
  int recoveries = 0;
  double recovery_sum = 0.0;
  for (const metrics::FailureRun& run : summary.failures) {
    if (run.recovered) ++recoveries, recovery_sum += run.length;
  }
  j["losses"] = static_cast<int>(summary.failures.size());
  j["mean_recovery_frames"] = recoveries > 0 ? recovery_sum / recoveries : 0.0;
  // The table frame's error: the estimated camera_T_table against the true one.
  const Rigid3 table_error = take.camera_T_table.Inverse() * take.estimated_camera_T_table;
  j["table_frame_rotation_deg"] =
      RotationAngle(Eigen::Quaterniond::Identity(), table_error.rotation) * kDegrees;
  j["table_frame_translation_m"] = table_error.translation.norm();
  // evo over the frames with a pose (the filled gaps are the compositor's, not the tracker's).
  std::vector<Rigid3> estimated, reference;
  for (int i = 0; i < frames; ++i) {
    if (take.status[i] == track::TrackStatus::kLost) continue;
    estimated.push_back(take.tracked.poses[i]);
    reference.push_back(take.truth.poses[i]);
  }
  j["ape_translation_m"] = metrics::ToJson(
      metrics::Statistics(metrics::AbsoluteTranslationErrors(estimated, reference)));
  // RPE over consecutive frames of the whole take, gaps filled as the compositor gets them.
  const metrics::RelativeErrors rpe =
      metrics::RelativePoseErrors(take.tracked.poses, take.truth.poses, 1);
  j["rpe_translation_m"] = metrics::ToJson(metrics::Statistics(rpe.translation));
  j["rpe_rotation_deg"] = metrics::ToJson(metrics::Statistics(rpe.rotation_deg));
  rotation_errors->insert(rotation_errors->end(), rotation.begin(), rotation.end());
  translation_errors->insert(translation_errors->end(), translation.begin(), translation.end());
  return j;
}

nlohmann::json AnnotationMetrics(const TakeRun& take, double frame_rate, double reaction_time) {
  const metrics::AnnotationErrors errors =
      metrics::CompareAnnotations(take.truth_annotation.values, take.read_annotation.values);
  nlohmann::json j = metrics::ToJson(errors);
  const auto found = std::count(take.slider_found.begin(), take.slider_found.end(), true);
  j["found_share"] =
      take.slider_found.empty() ? 0.0 : static_cast<double>(found) / take.slider_found.size();
  // The annotator's lag behind their own opinion, as the read values show it, against the
  // compositor's reaction shift (DESIGN.md: 0.3 s).
  const int frames = static_cast<int>(take.read_annotation.values.size());
  const std::span<const double> judgement(take.annotation.judgement.data(), frames);
  const int max_lag = std::min(60, frames - 3);
  if (max_lag >= 1) {
    j["reaction_lag_s"] =
        CrossCorrelationLag(judgement, take.read_annotation.values, max_lag) / frame_rate;
    j["true_reaction_lag_s"] =
        CrossCorrelationLag(judgement, take.truth_annotation.values, max_lag) / frame_rate;
  }
  j["reaction_shift_s"] = reaction_time;
  double delay = 0.0;
  for (int i = 0; i < frames; ++i) delay += take.annotation.delay[i];
  j["mean_true_delay_s"] = frames > 0 ? delay / frames : 0.0;
  return j;
}

// The montage's own metrics: costs, constraint, annotation use, segments, seams, quality.
nlohmann::json MontageMetrics(const montage::Montage& m, const std::vector<double>& quality,
                              const std::vector<Trajectory>& takes,
                              const std::vector<std::vector<double>>& take_quality,
                              double frame_rate, int blend_window) {
  // The compositor's summary (costs, the constraint's cost, segments; montage/compose.h) without
  // its timings, then what the montage achieved.
  nlohmann::json j = montage::SummaryToJson(m.summary, m.segments);
  j.erase("seconds");

  // Liked frames used: of the reference frames where some take is liked (warped annotation > 0),
  // the share whose chosen take is liked. Disliked frames avoided: of the reference frames where
  // some take is disliked (< 0) and some is not, the share whose chosen take is not disliked.
  const int n = static_cast<int>(m.labels.size());
  int liked_frames = 0, liked_used = 0, disliked_frames = 0, disliked_avoided = 0;
  for (int t = 0; t < n; ++t) {
    bool any_liked = false, any_disliked = false, any_not_disliked = false;
    for (const std::vector<double>& a : m.warped_annotations) {
      any_liked |= a[t] > 0;
      any_disliked |= a[t] < 0;
      any_not_disliked |= a[t] >= 0;
    }
    const double chosen = m.warped_annotations[m.labels[t]][t];
    if (any_liked) ++liked_frames, liked_used += chosen > 0;
    if (any_disliked && any_not_disliked) ++disliked_frames, disliked_avoided += chosen >= 0;
  }
  j["liked_frames"] = liked_frames;
  j["liked_used_share"] = liked_frames > 0 ? static_cast<double>(liked_used) / liked_frames : 1.0;
  j["disliked_frames"] = disliked_frames;
  j["disliked_avoided_share"] =
      disliked_frames > 0 ? static_cast<double>(disliked_avoided) / disliked_frames : 1.0;

  // Seams: the largest change within the blend window around each transition, against the
  // takes' own frame-to-frame changes (their 95th percentile and maximum).
  const metrics::MotionChanges changes =
      metrics::ComputeMotionChanges(m.trajectory.poses, frame_rate);
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
  nlohmann::json seams = nlohmann::json::array();
  for (size_t k = 1; k < m.segments.size(); ++k) {
    const int frame = m.segments[k].montage_first;
    seam_position.push_back(metrics::WindowMax(changes.position, frame, radius));
    seam_velocity.push_back(metrics::WindowMax(changes.velocity, frame, radius));
    seam_angular.push_back(metrics::WindowMax(changes.angular_velocity, frame, radius));
    seams.push_back({{"frame", frame},
                     {"from_take", m.segments[k - 1].take},
                     {"to_take", m.segments[k].take},
                     {"position_jump_m", seam_position.back()},
                     {"velocity_jump_m_per_s", seam_velocity.back()},
                     {"angular_velocity_jump_deg_per_s", seam_angular.back()}});
  }
  auto max_of = [](const std::vector<double>& v) {
    return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end());
  };
  nlohmann::json seam_summary;
  seam_summary["count"] = static_cast<int>(seam_position.size());
  const struct {
    const char* name;
    const std::vector<double>& seam;
    const std::vector<double>& own;
  } kinds[] = {{"position_jump_m", seam_position, own_position},
               {"velocity_jump_m_per_s", seam_velocity, own_velocity},
               {"angular_velocity_jump_deg_per_s", seam_angular, own_angular}};
  for (const auto& kind : kinds) {
    const double own_p95 = metrics::Quantile(kind.own, 0.95);
    seam_summary[kind.name] = {
        {"seam_max", max_of(kind.seam)},
        {"seam_mean", Mean(kind.seam)},
        {"takes_median", metrics::Quantile(kind.own, 0.5)},
        {"takes_p95", own_p95},
        {"takes_max", max_of(kind.own)},
        {"seam_max_over_takes_p95", own_p95 > 0 ? max_of(kind.seam) / own_p95 : 0.0}};
  }
  j["seams"] = seam_summary;
  j["seam_list"] = seams;

  // Latent quality (carried from the takes' frames) against each take's.
  j["mean_quality"] = Mean(quality);
  std::vector<double> take_means;
  for (const std::vector<double>& q : take_quality) take_means.push_back(Mean(q));
  j["take_mean_quality"] = take_means;
  const double best = max_of(take_means);
  j["quality_gain_over_best_take"] = Mean(quality) - best;
  j["quality_gain_over_mean_take"] = Mean(quality) - Mean(take_means);
  return j;
}

}  // namespace

nlohmann::json ComputeRunMetrics(const RunConfig& config, const AnimatorRun& run,
                                 const TriangleMesh& proxy_model,
                                 const TriangleMesh* practice_model) {
  const sim::RenderConfig& render = config.render;
  const double fps = render.performance.frame_rate;
  nlohmann::json j;
  j["scenario"] = {
      {"story", render.render.story},          {"object", render.render.object},
      {"animator", run.participant.index},     {"takes", static_cast<int>(run.takes.size())},
      {"practice", config.run.practice},       {"fidelity", EnumName(config.run.fidelity)}};
  // (Not rendered_frames: it counts the work of this process, 0 for takes that --resume loaded,
  // so it is in run.json's "seconds" with the timings; metrics.json is a function of the config.)

  // The proxy's metric points (ADD/ADD-S), from the model the sensor rendered.
  const auto points = metrics::MetricPoints(proxy_model);

  std::vector<double> rotation, translation, practice_rotation, practice_translation;
  nlohmann::json takes = nlohmann::json::array();
  std::vector<double> squared_slider;
  for (const TakeRun& take : run.takes) {
    nlohmann::json t;
    t["take"] = take.take;
    t["frames"] = static_cast<int>(take.truth.poses.size());
    t["skill"] = take.performed.skill;
    t["mean_quality"] = Mean(
        std::span<const double>(take.performed.quality.quality.data(), take.truth.poses.size()));
    t["flaws"] = static_cast<int>(take.performed.flaws.size());
    t["tracking"] = TrackingMetrics(take, points, config.metrics, &rotation, &translation);
    t["annotation"] = AnnotationMetrics(take, fps, config.montage.reaction_time);
    for (size_t i = 0; i < take.truth_annotation.values.size(); ++i) {
      const double d = take.read_annotation.values[i] - take.truth_annotation.values[i];
      squared_slider.push_back(d * d);
    }
    takes.push_back(t);
  }
  j["takes"] = takes;
  if (run.practice) {
    const auto practice_points = metrics::MetricPoints(*practice_model);
    j["practice"] = {{"take", run.practice->take},
                     {"frames", static_cast<int>(run.practice->truth.poses.size())},
                     {"mean_quality",
                      Mean(std::span<const double>(run.practice->performed.quality.quality.data(),
                                                   run.practice->truth.poses.size()))},
                     {"tracking", TrackingMetrics(*run.practice, practice_points, config.metrics,
                                                  &practice_rotation, &practice_translation)}};
  }

  // Pooled over the takes.
  int frames = 0, with_estimate = 0, successes = 0;
  for (const nlohmann::json& t : j["takes"]) {
    const int f = t["tracking"]["frames"].get<int>();
    frames += f;
    with_estimate += t["tracking"]["frames_with_estimate"].get<int>();
    successes += static_cast<int>(std::lround(t["tracking"]["success_rate"].get<double>() * f));
  }
  j["tracking"] = {
      {"frames", frames},
      {"estimated_share", frames > 0 ? static_cast<double>(with_estimate) / frames : 0.0},
      {"success_rate", frames > 0 ? static_cast<double>(successes) / frames : 0.0},
      {"rotation_deg", metrics::ToJson(metrics::Statistics(rotation))},
      {"translation_m", metrics::ToJson(metrics::Statistics(translation))}};
  double slider_sse = 0.0;
  for (double s : squared_slider) slider_sse += s;
  j["annotation"] = {
      {"frames", static_cast<int>(squared_slider.size())},
      {"rmse", squared_slider.empty() ? 0.0 : std::sqrt(slider_sse / squared_slider.size())}};

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
  nlohmann::json montage_json;
  montage_json["tracked"] =
      MontageMetrics(run.montage, run.montage_quality, tracked, take_quality, fps, window);
  montage_json["truth"] = MontageMetrics(run.truth_montage, run.truth_montage_quality, truth,
                                         take_quality, fps, window);
  // The montage from tracked data against the one from the ground truth: both are on the first
  // take's (the reference's) timeline, so their labels compare frame by frame.
  const std::vector<int>& a = run.montage.labels;
  const std::vector<int>& b = run.truth_montage.labels;
  int same = 0;
  for (size_t t = 0; t < std::min(a.size(), b.size()); ++t) same += a[t] == b[t];
  montage_json["tracked_vs_truth"] = {
      {"label_agreement", a.empty() ? 0.0 : static_cast<double>(same) / a.size()},
      {"segments_difference", static_cast<int>(run.montage.segments.size()) -
                                  static_cast<int>(run.truth_montage.segments.size())},
      {"frames_difference",
       run.montage.summary.montage_frames - run.truth_montage.summary.montage_frames},
      {"mean_quality_difference", Mean(run.montage_quality) - Mean(run.truth_montage_quality)}};
  j["montage"] = montage_json;
  return j;
}

nlohmann::json SecondsToJson(const AnimatorRun& run) {
  const StageSeconds& s = run.seconds;
  const double sessions = s.record + s.annotate;
  return {{"perform", s.perform},
          {"record", s.record},
          {"annotate", s.annotate},
          {"compose", s.compose},
          {"metrics", s.metrics},
          {"total", s.total},
          {"rendered_frames", run.rendered_frames},
          {"render_track_frames_per_second", sessions > 0 ? run.rendered_frames / sessions : 0.0}};
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
