#include "people/take_quality.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/error.h"

namespace mmh::people {
namespace {

double LogRatioScore(double measured, double target, double log_sd) {
  if (target <= 0.0) return 1.0;
  const double r = std::log(std::max(measured, 1e-4) / target);
  return std::exp(-r * r / (2 * log_sd * log_sd));
}

}  // namespace

void QualityOptions::Validate(const std::string& prefix) const {
  RequirePositive(window, prefix + ".window", "s");
  RequirePositive(path_sigma, prefix + ".path_sigma", "m");
  RequireProbability(off_area_factor, prefix + ".off_area_factor");
  RequirePositive(play_area_width, prefix + ".play_area_width", "m");
  RequirePositive(play_area_depth, prefix + ".play_area_depth", "m");
  RequirePositive(steadiness_scale, prefix + ".steadiness_scale", "m");
  RequireNonNegative(steadiness_weight, prefix + ".steadiness_weight");
  RequirePositive(feature_log_sd, prefix + ".feature_log_sd");
  RequirePositive(speed_log_sd, prefix + ".speed_log_sd");
  RequirePositive(stillness_speed, prefix + ".stillness_speed", "m/s");
  RequirePositive(hit_sigma, prefix + ".hit_sigma", "m");
  RequireProbability(kind_mismatch, prefix + ".kind_mismatch");
  RequireProbability(expression_floor, prefix + ".expression_floor");
  RequireProbability(motion_floor, prefix + ".motion_floor");
}

double TiltFromUpright(const Eigen::Quaterniond& table_R_proxy) {
  const double up = (table_R_proxy * Eigen::Vector3d::UnitZ()).z();
  return std::acos(std::clamp(up, -1.0, 1.0));
}

double FacingHeading(const Eigen::Quaterniond& table_R_proxy) {
  // The x axis stays horizontal while the figure tilts forwards or backwards (about x), so it
  // gives the heading even for a figure lying on its back; the front (−y) is x turned by −90°.
  const Eigen::Vector3d x_axis = table_R_proxy * Eigen::Vector3d::UnitX();
  return std::atan2(x_axis.y(), x_axis.x()) - std::numbers::pi / 2;
}

namespace {

// The trajectory's per-frame features every factor reads.
struct PoseFeatures {
  std::vector<Eigen::Vector3d> position;  // table frame
  std::vector<double> tilt;               // from upright [rad]
  std::vector<double> heading;            // unwrapped [rad], so ranges over a window are meaningful
  std::vector<double> residual2;          // squared horizontal tremor residual [m²]
};

PoseFeatures ComputePoseFeatures(const std::vector<Rigid3>& poses) {
  const int n = static_cast<int>(poses.size());
  PoseFeatures f;
  f.position.resize(n);
  f.tilt.resize(n);
  f.heading.resize(n);
  for (int i = 0; i < n; ++i) {
    f.position[i] = poses[i].translation;
    f.tilt[i] = TiltFromUpright(poses[i].rotation);
    f.heading[i] = FacingHeading(poses[i].rotation);
  }
  for (int i = 1; i < n; ++i) {
    f.heading[i] = f.heading[i - 1] + WrapAngle(f.heading[i] - f.heading[i - 1]);
  }
  // Tremor: residual of the horizontal position from its centred 7-frame mean (the vertical
  // carries the steps' bounce, which is wanted).
  f.residual2.assign(n, 0.0);
  for (int i = 0; i < n; ++i) {
    const int a = std::max(0, i - 3), b = std::min(n - 1, i + 3);
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (int k = a; k <= b; ++k) mean += f.position[k].head<2>();
    mean /= (b - a + 1);
    f.residual2[i] = (f.position[i].head<2>() - mean).squaredNorm();
  }
  return f;
}

// The features decided at the beat's end (a fall either went down or not): E of a fall, slip,
// get-up, turn or hit; 1 for the other beats.
double BeatEndScore(const QualityInputs& in, const PerformedSegment& segment,
                    const PoseFeatures& f, int window_frames, const QualityOptions& options) {
  const StoryObject& object = *in.object;
  const Beat& beat = object.beats[segment.script_beat];
  const BeatStyleTarget target = ScriptTarget(beat.kind);
  const int first = segment.first_frame, last = segment.last_frame;
  if (beat.kind == BeatKind::kFall || beat.kind == BeatKind::kSlip) {
    double reached = 0.0;
    for (int k = first; k <= last; ++k) reached = std::max(reached, f.tilt[k]);
    return LogRatioScore(reached, target.tilt, options.feature_log_sd);
  }
  if (beat.kind == BeatKind::kGetUp) return std::exp(-std::pow(f.tilt[last] / 0.2, 2));
  if (beat.kind == BeatKind::kTurn) {
    // Facing the next travelling beat's direction at the end.
    for (int next = segment.script_beat + 1; next < static_cast<int>(object.beats.size());
         ++next) {
      if (!Travels(object.beats[next].kind)) continue;
      const std::vector<Eigen::Vector2d> p = object.BeatPolyline(next);
      Eigen::Vector2d tangent;
      PolylinePoint(p, 0.0, &tangent);
      const double wanted = std::atan2(tangent.y(), tangent.x());
      return 0.5 * (1 + std::cos(f.heading[last] - wanted));
    }
    return 1.0;
  }
  if (beat.kind == BeatKind::kHit) {
    const auto& hit = in.hit_targets.size() > static_cast<std::size_t>(segment.script_beat)
                          ? in.hit_targets[segment.script_beat]
                          : std::nullopt;
    if (!hit) return 1.0;
    double best = std::numeric_limits<double>::infinity();
    for (int k = std::max(first, last - window_frames); k <= last; ++k) {
      best = std::min(best, (f.position[k] - *hit).norm());
    }
    return std::exp(-best * best / (2 * options.hit_sigma * options.hit_sigma));
  }
  return 1.0;
}

// One beat as the script asks for it: what every frame of its segment is measured against.
struct BeatScript {
  const Beat* beat = nullptr;
  BeatStyleTarget target;
  std::vector<Eigen::Vector2d> polyline;
  double length = 0.0;         // of the polyline [m]
  double nominal_speed = 0.0;  // length / the beat's duration [m/s]
  double end_score = 1.0;      // BeatEndScore
};

// P: the distance from the scripted path, reduced outside the play area.
double PathScore(const BeatScript& script, const Eigen::Vector2d& xy,
                 const QualityOptions& options) {
  const double d = DistanceToPolyline(script.polyline, xy);
  double path = std::exp(-d * d / (2 * options.path_sigma * options.path_sigma));
  if (std::abs(xy.x()) > 0.5 * options.play_area_width ||
      std::abs(xy.y()) > 0.5 * options.play_area_depth) {
    path *= options.off_area_factor;
  }
  return path;
}

// S over the window [a, b].
double SteadinessScore(const PoseFeatures& f, int a, int b, const QualityOptions& options) {
  double r2 = 0.0;
  for (int k = a; k <= b; ++k) r2 += f.residual2[k];
  const double rms = std::sqrt(r2 / (b - a + 1));
  return std::exp(-std::pow(rms / options.steadiness_scale, 2));
}

// E: the beat's characteristic feature over the window [a, b] around frame i, at the script's
// intensity.
double ExpressionScore(const BeatScript& script, const PoseFeatures& f, int i, int a, int b,
                       double intensity, const QualityOptions& options) {
  double z_min = f.position[a].z(), z_max = f.position[a].z(), tilt_max = 0.0;
  double h_min = f.heading[a], h_max = f.heading[a];
  for (int k = a; k <= b; ++k) {
    z_min = std::min(z_min, f.position[k].z());
    z_max = std::max(z_max, f.position[k].z());
    tilt_max = std::max(tilt_max, f.tilt[k]);
    h_min = std::min(h_min, f.heading[k]);
    h_max = std::max(h_max, f.heading[k]);
  }
  const BeatStyleTarget& target = script.target;
  double expression = 1.0;
  switch (script.beat->kind) {
    case BeatKind::kWalk:
    case BeatKind::kMarch:
    case BeatKind::kStroll:
    case BeatKind::kLimp:
    case BeatKind::kJump:
      expression = LogRatioScore(z_max - z_min, target.bounce * intensity, options.feature_log_sd);
      if (target.sway > 0) {
        expression = std::sqrt(expression * LogRatioScore(tilt_max, target.sway * intensity,
                                                          options.feature_log_sd));
      }
      break;
    case BeatKind::kLookAround:
      expression = LogRatioScore(0.5 * (h_max - h_min), target.yaw_swing * intensity,
                                 options.feature_log_sd);
      break;
    case BeatKind::kLie:
      expression = LogRatioScore(f.tilt[i], target.tilt, options.feature_log_sd);
      break;
    case BeatKind::kFall:
    case BeatKind::kSlip:
    case BeatKind::kGetUp:
    case BeatKind::kTurn:
    case BeatKind::kHit:
      expression = script.end_score;
      break;
    case BeatKind::kStand:
      break;
  }
  return expression;
}

// M: speed and direction of travel at progress u, or stillness, from the centred velocity over
// at most ±3 frames inside the window [a, b].
double MotionScore(const BeatScript& script, const PoseFeatures& f, int i, int a, int b, double u,
                   double dt, const QualityOptions& options) {
  const int c0 = std::max(a, i - 3), c1 = std::min(b, i + 3);
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();
  if (c1 > c0) velocity = (f.position[c1] - f.position[c0]).head<2>() / ((c1 - c0) * dt);
  const double speed = velocity.norm();
  const BeatKind kind = script.beat->kind;
  if (Travels(kind)) {
    Eigen::Vector2d tangent;
    PolylinePoint(script.polyline, script.length * u, &tangent);
    const double direction = speed > 1e-3 ? 0.5 * (1 + velocity.dot(tangent) / speed) : 0.5;
    return LogRatioScore(speed, script.nominal_speed, options.speed_log_sd) * direction;
  }
  if (kind != BeatKind::kTurn && kind != BeatKind::kLookAround) {
    return std::exp(-std::pow(speed / options.stillness_speed, 2));
  }
  return 1.0;
}

}  // namespace

QualityTrace ComputeTakeQuality(const QualityInputs& in, const QualityOptions& options) {
  const StoryObject& object = *in.object;
  const auto& poses = in.table_T_proxy->poses;
  const int n = static_cast<int>(poses.size());
  QualityTrace trace;
  for (auto* v : {&trace.quality, &trace.fidelity, &trace.path, &trace.steadiness,
                  &trace.expression, &trace.motion}) {
    v->assign(n, 0.0);
  }
  if (n == 0) return trace;
  const double dt = 1.0 / in.frame_rate;
  const int w = std::max(1, static_cast<int>(std::lround(options.window * in.frame_rate)));
  const PoseFeatures features = ComputePoseFeatures(poses);

  for (const PerformedSegment& segment : in.segments) {
    BeatScript script;
    script.beat = &object.beats[segment.script_beat];
    script.target = ScriptTarget(script.beat->kind);
    script.polyline = object.BeatPolyline(segment.script_beat);
    script.length = PolylineLength(script.polyline);
    script.nominal_speed = script.length / object.BeatDuration(segment.script_beat);
    script.end_score = BeatEndScore(in, segment, features, w, options);
    const int first = segment.first_frame, last = segment.last_frame;

    for (int i = first; i <= last; ++i) {
      const int a = std::max(first, i - w), b = std::min(last, i + w);
      const double u = in.script_progress[i];
      trace.fidelity[i] = segment.performed_kind == script.beat->kind ? 1.0 : options.kind_mismatch;
      trace.path[i] = PathScore(script, features.position[i].head<2>(), options);
      trace.steadiness[i] = SteadinessScore(features, a, b, options);
      trace.expression[i] =
          ExpressionScore(script, features, i, a, b, script.beat->IntensityAt(u), options);
      trace.motion[i] = MotionScore(script, features, i, a, b, u, dt, options);
      trace.quality[i] =
          trace.fidelity[i] * trace.path[i] *
          std::pow(trace.steadiness[i], options.steadiness_weight) *
          (options.expression_floor + (1 - options.expression_floor) * trace.expression[i]) *
          (options.motion_floor + (1 - options.motion_floor) * trace.motion[i]);
    }
  }
  return trace;
}

}  // namespace mmh::people
