#include "people/performance.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "core/error.h"
#include "people/random.h"

namespace mmh::people {
namespace {

constexpr double kPi = std::numbers::pi;
// Half the depth of a Duplo figure: a figure tilted by θ about its base lifts its origin by this
// times |sin θ| so that it lies on the table instead of in it.
constexpr double kHalfDepth = 0.016;
// Where in a hit beat the figure lands on the target's head (progress), and where its approach
// ends.
constexpr double kHitContact = 0.85;
constexpr double kHitApproachEnd = 0.7;

constexpr std::pair<FlawKind, const char*> kFlawNames[] = {
    {FlawKind::kHesitation, "hesitation"},
    {FlawKind::kOutOfOrder, "out_of_order"},
    {FlawKind::kMissed, "missed"},
    {FlawKind::kWrongDirection, "wrong_direction"},
    {FlawKind::kBotchedFall, "botched_fall"},
    {FlawKind::kOffArea, "off_area"},
};

double Mix(double unskilled, double skilled, double skill) {
  return unskilled + (skilled - unskilled) * skill;
}
double Smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3 - 2 * x);
}
// Travel progress: moving off and arriving gently, never stopping.
double Ease(double p) {
  p = std::clamp(p, 0.0, 1.0);
  return p - 0.25 * std::sin(2 * kPi * p) / (2 * kPi);
}

Eigen::Quaterniond AxisAngle(double angle, const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis));
}

bool IsGait(BeatKind kind) {
  return kind == BeatKind::kWalk || kind == BeatKind::kMarch || kind == BeatKind::kStroll ||
         kind == BeatKind::kLimp || kind == BeatKind::kHit;
}

// The animator's style in this take: multipliers of the script's targets.
struct TakeStyle {
  double bounce = 1, sway = 1, yaw = 1, tempo = 1;
};

// A sum of sinusoids with random frequencies and phases (tremor, wander): deterministic, smooth.
struct Oscillator {
  double frequency[3] = {}, phase[3] = {};
  void Draw(Random& random, double low_hz, double high_hz) {
    for (int k = 0; k < 3; ++k) {
      frequency[k] = random.Uniform(low_hz, high_hz);
      phase[k] = random.Uniform(0, 2 * kPi);
    }
  }
  double operator()(double t) const {
    double sum = 0;
    for (int k = 0; k < 3; ++k) sum += std::sin(2 * kPi * frequency[k] * t + phase[k]);
    return sum / std::sqrt(1.5);  // unit RMS
  }
};

// What the animator will do for one script beat.
struct Segment {
  int script_beat = 0;
  BeatKind kind = BeatKind::kStand;  // performed
  double duration = 0;               // [s] without the hesitation
  double amplitude = 1;              // multiplies the style targets
  double fall_tilt = kPi / 2;        // [rad] fall: tilt reached
  bool wrong_direction = false;
  double hesitation_at = 0, hesitation_length = 0;  // progress, [s]
  bool off_area = false;
  double off_from = 0, off_size = 0;
  std::vector<Eigen::Vector2d> polyline;  // performed path (travelling beats)
  std::optional<Eigen::Vector3d> hit_target;
  std::vector<FlawKind> flaws;

  double TotalSeconds() const { return duration + hesitation_length; }
  // Progress in the beat at local time tau (a hesitation holds it).
  double Progress(double tau) const {
    const double at = hesitation_at * duration;
    if (tau < at) return tau / duration;
    if (tau < at + hesitation_length) return hesitation_at;
    return std::min(1.0, (tau - hesitation_length) / duration);
  }
  bool Hesitating(double tau) const {
    const double at = hesitation_at * duration;
    return hesitation_length > 0 && tau >= at && tau < at + hesitation_length;
  }
};

struct Plan {
  double skill = 0;
  TakeStyle style;
  std::vector<Segment> segments;
  Oscillator tremor[6];  // x, y, z, rotation about x, y, z
  Oscillator wander[2];
  double tremor_amplitude = 0, wander_amplitude = 0;
};

Plan PlanTake(const StoryObject& object, const AnimatorProfile& animator, int take,
              const PerformanceOptions& options, Random& random) {
  Plan plan;
  const double s = animator.SkillAtTake(take);
  plan.skill = s;
  const double energy_gain = 0.6 + 0.8 * animator.energy;
  plan.style.bounce =
      animator.bounce_style * energy_gain * std::exp(random.Normal(0, options.take_style_sd));
  plan.style.sway =
      animator.sway_style * energy_gain * std::exp(random.Normal(0, options.take_style_sd));
  plan.style.yaw =
      animator.yaw_style * energy_gain * std::exp(random.Normal(0, options.take_style_sd));
  plan.style.tempo = animator.tempo_style * (0.85 + 0.3 * animator.energy) *
                     std::exp(random.Normal(0, 0.5 * options.take_style_sd));
  for (auto& o : plan.tremor) o.Draw(random, 6.0, 11.0);
  for (auto& o : plan.wander) o.Draw(random, 0.1, 0.4);
  plan.tremor_amplitude = Mix(options.tremor_unskilled, options.tremor_skilled, s);
  plan.wander_amplitude = Mix(options.wander_unskilled, options.wander_skilled, s);

  const double timing_sd = Mix(options.timing_sd_unskilled, options.timing_sd_skilled, s);
  const double amplitude_sd = Mix(options.amplitude_sd_unskilled, options.amplitude_sd_skilled, s);
  const double flaw = 1 - s;
  const int beats = static_cast<int>(object.beats.size());
  for (int i = 0; i < beats; ++i) {
    Segment seg;
    seg.script_beat = i;
    seg.kind = object.beats[i].kind;
    // Tempo shortens gait beats only; the script's pauses keep their length.
    const double tempo = Travels(seg.kind) ? plan.style.tempo : 1.0;
    seg.duration = object.BeatDuration(i) * std::exp(random.Normal(0, timing_sd)) / tempo;
    seg.amplitude = std::exp(random.Normal(0, amplitude_sd));
    seg.fall_tilt = kPi / 2;
    seg.polyline = object.BeatPolyline(i);
    plan.segments.push_back(seg);
  }
  // Flaws, each decided with its own draws in a fixed order (reproducible).
  for (int i = 0; i < beats; ++i) {
    Segment& seg = plan.segments[i];
    const double u_hesitate = random.Uniform();
    const double u_order = random.Uniform();
    const double u_missed = random.Uniform();
    const double u_direction = random.Uniform();
    const double u_fall = random.Uniform();
    const double u_off = random.Uniform();
    const double at = random.Uniform(0.25, 0.75);
    const double length = random.Exponential(options.hesitation_seconds);
    const double fall = random.Uniform(0.25, 0.6);
    const double off_size = random.Uniform(0.04, 0.07);
    // A hesitation stops the figure on its way for a moment.
    if (Travels(seg.kind) && seg.kind != BeatKind::kHit &&
        u_hesitate < options.hesitation_rate * flaw && seg.duration > 1.5) {
      seg.hesitation_at = at;
      seg.hesitation_length = std::clamp(length, 0.4, 3.0);
      seg.flaws.push_back(FlawKind::kHesitation);
    }
    const bool already_reordered =
        !seg.flaws.empty() &&
        std::count(seg.flaws.begin(), seg.flaws.end(), FlawKind::kOutOfOrder) > 0;
    if (!already_reordered && i + 1 < beats && u_order < options.out_of_order_rate * flaw) {
      Segment& next = plan.segments[i + 1];
      // Swapping is only possible between beats of the same sort (both travel or both in place)
      // and of different kinds.
      if (Travels(seg.kind) == Travels(next.kind) && seg.kind != next.kind &&
          seg.kind != BeatKind::kHit && next.kind != BeatKind::kHit) {
        std::swap(seg.kind, next.kind);
        seg.flaws.push_back(FlawKind::kOutOfOrder);
        next.flaws.push_back(FlawKind::kOutOfOrder);
        continue;
      }
    }
    if (!already_reordered && i > 0 && seg.kind != BeatKind::kHit &&
        u_missed < options.missed_rate * flaw) {
      // Carries on with the previous action (or stands), hurried.
      BeatKind carry = BeatKind::kStand;
      if (Travels(seg.kind)) {
        carry = BeatKind::kWalk;
        for (int k = i - 1; k >= 0; --k) {
          if (Travels(plan.segments[k].kind) && plan.segments[k].kind != BeatKind::kHit) {
            carry = plan.segments[k].kind;
            break;
          }
        }
      }
      if (carry != seg.kind) {
        seg.kind = carry;
        seg.duration *= 0.4;
        seg.flaws.push_back(FlawKind::kMissed);
      }
    }
    if (Travels(seg.kind) && seg.kind != BeatKind::kHit &&
        u_direction < options.wrong_direction_rate * flaw) {
      seg.wrong_direction = true;
      seg.flaws.push_back(FlawKind::kWrongDirection);
    }
    if (object.beats[i].kind == BeatKind::kFall && seg.kind == BeatKind::kFall &&
        u_fall < options.botched_fall_rate * flaw) {
      seg.fall_tilt = fall;
      seg.flaws.push_back(FlawKind::kBotchedFall);
    }
    if (Travels(seg.kind) && seg.kind != BeatKind::kHit && u_off < options.off_area_rate * flaw) {
      seg.off_area = true;
      seg.off_from = at - 0.2;
      seg.off_size = off_size;
      seg.flaws.push_back(FlawKind::kOffArea);
    }
    if (seg.wrong_direction && seg.polyline.size() >= 2 &&
        (seg.polyline.front() - seg.polyline.back()).norm() < 1e-6) {
      // A round: the other way round.
      std::reverse(seg.polyline.begin(), seg.polyline.end());
    }
  }
  return plan;
}

// Generates the frames of a planned take; fills the trajectory, per-frame beat, kind, progress
// and the performed segments' frame ranges.
struct Generated {
  Trajectory table_T_proxy;
  std::vector<int> script_beat;
  std::vector<BeatKind> kind;
  std::vector<double> progress;
  std::vector<PerformedSegment> segments;
  std::vector<Flaw> flaws;
};

// The figure's state, carried from frame to frame while a take is generated.
struct Figure {
  Eigen::Vector2d position;
  Eigen::Vector2d previous;
  double heading = 0, heading_target = 0;
  double pitch = 0, roll = 0, z = 0, yaw_extra = 0;
  double step_phase = 0;
  double turn_from = 0;
  double segment_pitch = 0;
  // The current segment's path from where the figure actually stood when it began (after a hit
  // it stands where the target was), set once per segment.
  std::vector<Eigen::Vector2d> polyline;
  double length = 0;
  Eigen::Vector2d start_tangent = Eigen::Vector2d::Zero();
  bool closed = false;
};

// At the object's start waypoint, facing along the first travelling beat.
Figure StartFigure(const StoryObject& object, const std::vector<Segment>& segments) {
  Figure f;
  f.position = object.path[object.start_waypoint];
  f.previous = f.position;
  for (const Segment& seg : segments) {
    if (seg.polyline.size() >= 2) {
      Eigen::Vector2d tangent;
      PolylinePoint(seg.polyline, 0.0, &tangent);
      f.heading = f.heading_target = std::atan2(tangent.y(), tangent.x());
      break;
    }
  }
  f.turn_from = f.heading;
  return f;
}

// A new segment starts from where the last one left the figure.
void BeginSegment(const Segment& seg, Figure& f) {
  f.turn_from = f.heading;
  f.segment_pitch = f.pitch;
  f.polyline.clear();
  if (seg.polyline.size() >= 2 || seg.hit_target) {
    f.closed = (seg.polyline.front() - seg.polyline.back()).norm() < 1e-6;
    f.polyline = seg.polyline;
    f.polyline.front() = f.position;
    if (seg.hit_target) f.polyline = {f.position, seg.hit_target->head<2>()};
    f.length = PolylineLength(f.polyline);
    PolylinePoint(f.polyline, 0.0, &f.start_tangent);
  }
}

// Where the figure stands at progress p of the segment.
void Place(const Segment& seg, double p, Figure& f) {
  if (f.polyline.empty()) return;
  if (seg.kind == BeatKind::kHit || seg.hit_target) {
    f.position = PolylinePoint(f.polyline, f.length * Ease(std::min(p / kHitApproachEnd, 1.0)));
  } else if (seg.wrong_direction && !f.closed) {
    // Sets off the wrong way, notices, comes back, then does the beat in the time left.
    if (p < 0.5) {
      f.position = f.polyline.front() - f.start_tangent * 0.35 * f.length * std::sin(kPi * p / 0.5);
    } else {
      f.position = PolylinePoint(f.polyline, f.length * Ease((p - 0.5) / 0.5));
    }
  } else {
    f.position = PolylinePoint(f.polyline, f.length * Ease(p));
  }
  if (seg.off_area && p > seg.off_from && p < seg.off_from + 0.3) {
    const Eigen::Vector2d outward = f.position.norm() > 1e-6
                                        ? Eigen::Vector2d(f.position.normalized())
                                        : Eigen::Vector2d::UnitY();
    f.position += outward * seg.off_size * std::sin(kPi * (p - seg.off_from) / 0.3);
  }
}

// Where it faces: along its steps, or (a turn) towards the next travelling beat's direction;
// the heading follows its target with a first-order lag (heading_gain per frame).
void Face(const std::vector<Segment>& segments, int k, double p, double heading_gain,
          Figure& f) {
  const Segment& seg = segments[k];
  const Eigen::Vector2d step = f.position - f.previous;
  if (Travels(seg.kind) && step.norm() > 0.0003) {
    f.heading_target = std::atan2(step.y(), step.x());
  }
  if (seg.kind == BeatKind::kTurn) {
    double wanted = f.turn_from;
    for (std::size_t n = k + 1; n < segments.size(); ++n) {
      if (segments[n].polyline.size() >= 2) {
        Eigen::Vector2d tangent;
        PolylinePoint(segments[n].polyline, 0.0, &tangent);
        wanted = std::atan2(tangent.y(), tangent.x());
        break;
      }
    }
    f.heading_target = f.turn_from + WrapAngle(wanted - f.turn_from) * Smoothstep(p);
  }
  f.heading += WrapAngle(f.heading_target - f.heading) * heading_gain;
  f.previous = f.position;
}

// Steps, hops, sway, head turns and tilt at time tau (progress p) into the segment; height, roll
// and yaw follow their targets with a first-order lag (smooth_gain per frame).
void Animate(const StoryObject& object, const Plan& plan, const Segment& seg, double tau,
             double p, bool hesitating, double dt, double smooth_gain, Figure& f) {
  const Beat& beat = object.beats[seg.script_beat];
  const double intensity = seg.amplitude * beat.IntensityAt(p);
  const BeatStyleTarget target = ScriptTarget(seg.kind);
  double z_target = 0, roll_target = 0, yaw_target = 0;
  const bool moving = !hesitating;
  if (moving && (IsGait(seg.kind) || seg.kind == BeatKind::kJump)) {
    f.step_phase += target.step_rate * plan.style.tempo * dt;
  }
  switch (seg.kind) {
    case BeatKind::kWalk:
    case BeatKind::kMarch:
    case BeatKind::kStroll:
    case BeatKind::kLimp: {
      double rise =
          target.bounce * intensity * plan.style.bounce * std::abs(std::sin(kPi * f.step_phase));
      if (seg.kind == BeatKind::kLimp && static_cast<long>(std::floor(f.step_phase)) % 2 == 1) {
        rise *= 0.4;  // the bad leg's short step
      }
      if (moving) z_target = rise;
      const double sway = target.sway * intensity * plan.style.sway;
      if (seg.kind == BeatKind::kStroll) roll_target = sway * std::sin(kPi * f.step_phase);
      if (seg.kind == BeatKind::kLimp) {
        roll_target = sway * (0.6 + 0.4 * std::sin(kPi * f.step_phase));
      }
      break;
    }
    case BeatKind::kJump: {
      const double phase = f.step_phase - std::floor(f.step_phase);
      if (moving) {
        z_target = target.bounce * intensity * plan.style.bounce * 4 * phase * (1 - phase);
      }
      break;
    }
    case BeatKind::kHit: {
      const double top = seg.hit_target ? seg.hit_target->z() : object.height;
      if (p < kHitApproachEnd) {
        z_target = ScriptTarget(BeatKind::kWalk).bounce * plan.style.bounce *
                   std::abs(std::sin(kPi * f.step_phase));
      } else {
        z_target = top * std::sin(kPi * (p - kHitApproachEnd) / (1 - kHitApproachEnd));
      }
      break;
    }
    case BeatKind::kLookAround:
      yaw_target = ScriptTarget(BeatKind::kLookAround).yaw_swing * intensity * plan.style.yaw *
                   std::sin(2 * kPi * 0.35 * tau) * std::sqrt(std::sin(kPi * p));
      break;
    default:
      break;
  }
  switch (seg.kind) {
    case BeatKind::kSlip:
      f.pitch = f.segment_pitch + (-target.tilt * seg.amplitude - f.segment_pitch) * Smoothstep(p);
      break;
    case BeatKind::kFall:
      f.pitch = f.segment_pitch + (-seg.fall_tilt - f.segment_pitch) * p * p;
      break;
    case BeatKind::kLie:
      f.pitch = f.segment_pitch;
      break;
    case BeatKind::kGetUp:
      f.pitch = f.segment_pitch * (1 - Smoothstep(p)) +
                0.06 * (1 - plan.skill) * std::sin(2 * kPi * 1.5 * tau) * std::sin(kPi * p);
      break;
    default:
      f.pitch *= std::exp(-dt / 0.25);  // stands up straight again
      break;
  }
  f.z += (z_target - f.z) * smooth_gain;
  f.roll += (roll_target - f.roll) * smooth_gain;
  f.yaw_extra += (yaw_target - f.yaw_extra) * smooth_gain;
}

// table_T_proxy at time t: the figure's pose as the hand holds it, with the hand's slow wander
// and tremor.
Rigid3 HeldPose(const Figure& f, const Plan& plan, const PerformanceOptions& options, double t) {
  Eigen::Vector3d xyz(f.position.x(), f.position.y(),
                      f.z + kHalfDepth * std::abs(std::sin(f.pitch)));
  xyz.x() += plan.wander_amplitude * plan.wander[0](t);
  xyz.y() += plan.wander_amplitude * plan.wander[1](t);
  for (int a = 0; a < 3; ++a) xyz[a] += plan.tremor_amplitude * plan.tremor[a](t);
  // The table stops the figure: the tremor can lift it, never push it in.
  xyz.z() = std::max(xyz.z(), kHalfDepth * std::abs(std::sin(f.pitch)));
  const double angle = plan.tremor_amplitude * options.tremor_angle;
  const Eigen::Quaterniond tremor =
      AxisAngle(angle * plan.tremor[3](t), Eigen::Vector3d::UnitX()) *
      AxisAngle(angle * plan.tremor[4](t), Eigen::Vector3d::UnitY()) *
      AxisAngle(angle * plan.tremor[5](t), Eigen::Vector3d::UnitZ());
  // yaw = heading + π/2: the figure's front (−y) faces the heading (docs/notation.md).
  const Eigen::Quaterniond rotation =
      AxisAngle(f.heading + kPi / 2 + f.yaw_extra, Eigen::Vector3d::UnitZ()) *
      AxisAngle(f.pitch, Eigen::Vector3d::UnitX()) * AxisAngle(f.roll, Eigen::Vector3d::UnitY()) *
      tremor;
  return Rigid3(rotation.normalized(), xyz);
}

// The planned flaws with the frames they affect, within their performed segments.
std::vector<Flaw> FlawFrames(const std::vector<Segment>& segments,
                             const std::vector<double>& seg_start,
                             const std::vector<PerformedSegment>& performed_segments,
                             const PerformanceOptions& options) {
  std::vector<Flaw> flaws;
  for (const PerformedSegment& performed : performed_segments) {
    int k = 0;
    while (segments[k].script_beat != performed.script_beat) ++k;
    const Segment& seg = segments[k];
    for (const FlawKind kind : seg.flaws) {
      Flaw flaw{kind, seg.script_beat, performed.first_frame, performed.last_frame};
      const double t0 = seg_start[k];
      if (kind == FlawKind::kHesitation) {
        const double at = t0 + seg.hesitation_at * seg.duration;
        flaw.first_frame = static_cast<int>(std::ceil(at * options.frame_rate));
        flaw.last_frame = static_cast<int>((at + seg.hesitation_length) * options.frame_rate);
      } else if (kind == FlawKind::kOffArea) {
        // Progress runs linearly in time outside a hesitation.
        const auto frame_at = [&](double progress) {
          double tau = progress * seg.duration;
          if (progress > seg.hesitation_at) tau += seg.hesitation_length;
          return static_cast<int>(std::lround((t0 + tau) * options.frame_rate));
        };
        flaw.first_frame = frame_at(seg.off_from);
        flaw.last_frame = frame_at(seg.off_from + 0.3);
      }
      flaw.first_frame = std::clamp(flaw.first_frame, performed.first_frame, performed.last_frame);
      flaw.last_frame = std::clamp(flaw.last_frame, flaw.first_frame, performed.last_frame);
      flaws.push_back(flaw);
    }
  }
  return flaws;
}

Generated Generate(const StoryObject& object, const Plan& plan, int frames,
                   const PerformanceOptions& options) {
  Generated out;
  const double dt = 1.0 / options.frame_rate;
  const std::vector<Segment>& segments = plan.segments;
  std::vector<double> seg_start(segments.size() + 1, 0.0);
  for (std::size_t k = 0; k < segments.size(); ++k) {
    seg_start[k + 1] = seg_start[k] + segments[k].TotalSeconds();
  }
  Figure figure = StartFigure(object, segments);
  int current = -1;
  const double heading_gain = 1 - std::exp(-dt / options.heading_time_constant);
  const double smooth_gain = 1 - std::exp(-dt / 0.04);
  for (int i = 0; i < frames; ++i) {
    const double t = i * dt;
    int k = current < 0 ? 0 : current;
    while (k + 1 < static_cast<int>(segments.size()) && t >= seg_start[k + 1]) ++k;
    const Segment& seg = segments[k];
    if (k != current) {
      if (!out.segments.empty()) out.segments.back().last_frame = i - 1;
      out.segments.push_back({seg.script_beat, seg.kind, i, i});
      current = k;
      BeginSegment(seg, figure);
    }
    const double tau = t - seg_start[k];
    const double p = seg.Progress(tau);
    Place(seg, p, figure);
    Face(segments, k, p, heading_gain, figure);
    Animate(object, plan, seg, tau, p, seg.Hesitating(tau), dt, smooth_gain, figure);
    out.table_T_proxy.timestamps.push_back(t);
    out.table_T_proxy.poses.push_back(HeldPose(figure, plan, options, t));
    out.script_beat.push_back(seg.script_beat);
    out.kind.push_back(seg.kind);
    out.progress.push_back(p);
  }
  if (!out.segments.empty()) out.segments.back().last_frame = frames - 1;
  out.flaws = FlawFrames(segments, seg_start, out.segments, options);
  return out;
}

// The performed segments (maximal runs of one script beat and one action) of a take.
std::vector<PerformedSegment> SegmentsOf(const PerformedTake& take) {
  std::vector<PerformedSegment> segments;
  for (int i = 0; i < take.frames(); ++i) {
    if (segments.empty() || segments.back().script_beat != take.script_beat[i] ||
        segments.back().performed_kind != take.performed_kind[i]) {
      segments.push_back({take.script_beat[i], take.performed_kind[i], i, i});
    }
    segments.back().last_frame = i;
  }
  return segments;
}

PerformedTake Finish(const StoryObject& object, int object_index, int take, const Plan& plan,
                     Generated generated, const PerformanceOptions& options,
                     std::vector<std::optional<Eigen::Vector3d>> hit_targets) {
  PerformedTake result;
  result.take = take;
  result.object = object_index;
  result.skill = plan.skill;
  result.table_T_proxy = std::move(generated.table_T_proxy);
  result.script_beat = std::move(generated.script_beat);
  result.performed_kind = std::move(generated.kind);
  result.script_progress = std::move(generated.progress);
  result.hit_targets = std::move(hit_targets);
  result.hit_targets.resize(object.beats.size());
  result.flaws = std::move(generated.flaws);
  result.quality =
      MeasureQuality(object, result, result.table_T_proxy, options.quality, options.frame_rate);
  return result;
}

void RequireObject(const Story& story, int object) {
  if (object < 0 || object >= static_cast<int>(story.objects.size())) {
    ThrowBadValue(story.file + ": object", std::to_string(object),
                  "an object index in [0, " + std::to_string(story.objects.size() - 1) + "]");
  }
}

}  // namespace

std::span<const std::pair<FlawKind, const char*>> EnumNames(FlawKind) { return kFlawNames; }

double AnimatorProfile::SkillAtTake(int take) const {
  return 1 - (1 - skill) * std::pow(1 - learning, std::max(take, 0));
}

void AnimatorProfile::Validate(const std::string& prefix) const {
  RequireProbability(skill, prefix + ".skill");
  RequireProbability(energy, prefix + ".energy");
  RequireProbability(learning, prefix + ".learning");
  RequirePositive(bounce_style, prefix + ".bounce_style");
  RequirePositive(sway_style, prefix + ".sway_style");
  RequirePositive(yaw_style, prefix + ".yaw_style");
  RequirePositive(tempo_style, prefix + ".tempo_style");
}

void PerformanceOptions::Validate(const std::string& prefix) const {
  if (!(frame_rate >= 1 && frame_rate <= 1000)) {
    ThrowBadValue(prefix + ".frame_rate", FormatNumber(frame_rate), "a rate in [1, 1000] Hz");
  }
  for (const auto& [value, name] : {std::pair{timing_sd_unskilled, "timing_sd_unskilled"},
                                    {timing_sd_skilled, "timing_sd_skilled"},
                                    {amplitude_sd_unskilled, "amplitude_sd_unskilled"},
                                    {amplitude_sd_skilled, "amplitude_sd_skilled"},
                                    {take_style_sd, "take_style_sd"},
                                    {tremor_unskilled, "tremor_unskilled"},
                                    {tremor_skilled, "tremor_skilled"},
                                    {tremor_angle, "tremor_angle"},
                                    {wander_unskilled, "wander_unskilled"},
                                    {wander_skilled, "wander_skilled"}}) {
    RequireNonNegative(value, prefix + "." + name);
  }
  for (const auto& [value, name] : {std::pair{hesitation_rate, "hesitation_rate"},
                                    {out_of_order_rate, "out_of_order_rate"},
                                    {missed_rate, "missed_rate"},
                                    {wrong_direction_rate, "wrong_direction_rate"},
                                    {botched_fall_rate, "botched_fall_rate"},
                                    {off_area_rate, "off_area_rate"}}) {
    RequireProbability(value, prefix + "." + name);
  }
  RequirePositive(hesitation_seconds, prefix + ".hesitation_seconds", "s");
  RequirePositive(heading_time_constant, prefix + ".heading_time_constant", "s");
  quality.Validate(prefix + ".quality");
}

QualityTrace MeasureQuality(const StoryObject& object, const PerformedTake& take,
                            const Trajectory& motion, const QualityOptions& options,
                            double frame_rate) {
  if (motion.poses.size() != take.table_T_proxy.poses.size()) {
    ThrowBadValue("motion measured against take " + std::to_string(take.take),
                  std::to_string(motion.poses.size()) + " poses",
                  "one per frame of the take (" + std::to_string(take.frames()) + ")");
  }
  QualityInputs inputs;
  inputs.object = &object;
  inputs.table_T_proxy = &motion;
  inputs.frame_rate = frame_rate;
  inputs.segments = SegmentsOf(take);
  inputs.script_progress = take.script_progress;
  inputs.hit_targets = take.hit_targets;
  return ComputeTakeQuality(inputs, options);
}

double PerformedTake::MeanQuality() const {
  if (quality.quality.empty()) return 0.0;
  double sum = 0;
  for (const double q : quality.quality) sum += q;
  return sum / quality.quality.size();
}

PerformedTake PerformTake(const Story& story, int object, const AnimatorProfile& animator, int take,
                          const PerformanceOptions& options, std::uint64_t seed) {
  RequireObject(story, object);
  animator.Validate("animator");
  options.Validate("performance");
  const StoryObject& o = story.objects[object];
  for (std::size_t i = 0; i < o.beats.size(); ++i) {
    if (o.beats[i].kind == BeatKind::kHit) {
      ThrowBadValue(
          story.file + ": objects[" + std::to_string(object) + "] (\"" + o.name + "\")",
          "a layered object (beat " + std::to_string(i) + " hits \"" + o.beats[i].target + "\")",
          "an object without hit beats: a layered object's takes are made by "
          "PerformLayeredTake from the earlier objects' montage, which a single "
          "recording does not have");
    }
  }
  Random random(DeriveSeed(
      seed, {0x7a4eull, static_cast<std::uint64_t>(object), static_cast<std::uint64_t>(take)}));
  const Plan plan = PlanTake(o, animator, take, options, random);
  double total = 0;
  for (const Segment& seg : plan.segments) total += seg.TotalSeconds();
  const int frames = std::max(1, static_cast<int>(std::lround(total * options.frame_rate)));
  return Finish(o, object, take, plan, Generate(o, plan, frames, options), options, {});
}

PerformedTake PerformLayeredTake(const Story& story, int object, const AnimatorProfile& animator,
                                 int take, int frames, std::span<const Trajectory> earlier_montages,
                                 const PerformanceOptions& options, std::uint64_t seed,
                                 int min_marker_gap) {
  RequireObject(story, object);
  animator.Validate("animator");
  options.Validate("performance");
  const StoryObject& o = story.objects[object];
  if (frames < 2) ThrowBadValue("layered take length", std::to_string(frames), "at least 2 frames");
  Random random(DeriveSeed(
      seed, {0x7a4eull, static_cast<std::uint64_t>(object), static_cast<std::uint64_t>(take)}));
  Plan plan = PlanTake(o, animator, take, options, random);
  const double fps = options.frame_rate;
  const double length = frames / fps;
  const double scale = length / o.end;

  // Spatial markers: where on the montage's timeline each interaction should happen (placed by
  // the animator before recording, a little off the script's nominal time).
  struct Anchor {
    int segment;
    int marker;
  };
  std::vector<Anchor> anchors;
  std::vector<int> markers;
  Random marker_random(DeriveSeed(seed, {0x6d61ull, static_cast<std::uint64_t>(object)}));
  for (std::size_t k = 0; k < plan.segments.size(); ++k) {
    const int beat = plan.segments[k].script_beat;
    if (o.beats[beat].kind != BeatKind::kHit) continue;
    const double nominal = (o.beats[beat].start + kHitContact * o.BeatDuration(beat)) * scale;
    int marker = static_cast<int>(
        std::lround((nominal + marker_random.Normal(0, 0.3 * (1 - animator.skill))) * fps));
    if (!markers.empty()) marker = std::max(marker, markers.back() + min_marker_gap);
    marker = std::clamp(marker, 1, frames - 2);
    if (!markers.empty() && marker - markers.back() < min_marker_gap) {
      ThrowBadValue(
          story.file + ": objects[" + std::to_string(object) + "].beats[" + std::to_string(beat) +
              "]",
          "a hit " + std::to_string(marker - markers.back()) + " frames after the previous marker",
          "spatial markers at least " + std::to_string(min_marker_gap) +
              " frames apart within the " + std::to_string(frames) + "-frame montage");
    }
    markers.push_back(marker);
    anchors.push_back({static_cast<int>(k), marker});
  }

  // Timing: the animator paces the take to fill the montage's length and to land each hit on its
  // marker (with a timing error that shrinks with skill). Segments between anchors are scaled.
  Random timing_random(DeriveSeed(
      seed, {0x7469ull, static_cast<std::uint64_t>(object), static_cast<std::uint64_t>(take)}));
  const double contact_sd = 0.25 * (1 - plan.skill);
  double done = 0;  // [s] of the take already paced
  std::size_t from = 0;
  std::vector<double> contact_times;
  for (const Anchor& anchor : anchors) {
    Segment& hit = plan.segments[anchor.segment];
    hit.hesitation_length = 0;  // an aimed jump does not pause
    double natural = kHitContact * hit.duration;
    for (int k = static_cast<int>(from); k < anchor.segment; ++k) {
      natural += plan.segments[k].TotalSeconds();
    }
    const double contact = std::clamp(anchor.marker / fps + timing_random.Normal(0, contact_sd),
                                      done + 0.5, length - 0.5);
    const double factor = (contact - done) / natural;
    for (int k = static_cast<int>(from); k <= anchor.segment; ++k) {
      plan.segments[k].duration *= factor;
      plan.segments[k].hesitation_length *= factor;
    }
    done = contact + (1 - kHitContact) * hit.duration;
    contact_times.push_back(contact);
    from = anchor.segment + 1;
  }
  double rest = 0;
  for (std::size_t k = from; k < plan.segments.size(); ++k) rest += plan.segments[k].TotalSeconds();
  if (from < plan.segments.size()) {
    const double factor = std::max(length - done, 0.2) / rest;
    for (std::size_t k = from; k < plan.segments.size(); ++k) {
      plan.segments[k].duration *= factor;
      plan.segments[k].hesitation_length *= factor;
    }
  }

  // Hit targets: the animator aims at where the marker shows the target; the hit lands where the
  // target actually is at the moment of contact.
  std::vector<std::optional<Eigen::Vector3d>> landed(o.beats.size());
  for (std::size_t a = 0; a < anchors.size(); ++a) {
    Segment& hit = plan.segments[anchors[a].segment];
    const Beat& beat = o.beats[hit.script_beat];
    const int target = story.ObjectIndex(beat.target);
    if (target >= static_cast<int>(earlier_montages.size()) ||
        static_cast<int>(earlier_montages[target].poses.size()) != frames) {
      ThrowBadValue("layered take of \"" + o.name + "\": montage of \"" + beat.target + "\"",
                    target < static_cast<int>(earlier_montages.size())
                        ? std::to_string(earlier_montages[target].poses.size()) + " frames"
                        : "missing",
                    "the earlier object's montage with " + std::to_string(frames) + " frames");
    }
    const double top = story.objects[target].height;
    const auto top_at = [&](int frame) {
      const Rigid3& pose = earlier_montages[target].poses[std::clamp(frame, 0, frames - 1)];
      return Eigen::Vector3d(pose.translation.x(), pose.translation.y(), top);
    };
    hit.hit_target = top_at(anchors[a].marker);
    landed[hit.script_beat] = top_at(static_cast<int>(std::lround(contact_times[a] * fps)));
  }

  PerformedTake result =
      Finish(o, object, take, plan, Generate(o, plan, frames, options), options, landed);
  result.markers = markers;
  return result;
}

}  // namespace mmh::people
