// The latent quality of a take: per frame, how well this moment realises the script. It is
// measured from the performed motion against what the script asks at that moment (never assigned):
//
//   q(t) = F(t) · P(t) · S(t)^w_s · (a + (1 − a)·E(t)) · (b + (1 − b)·M(t))
//
//   F  fidelity: 1 when the animator performs the scripted beat, `kind_mismatch` when they do
//      another (a beat out of order or missed);
//   P  path: exp(−d²/2σ_p²), d the distance of the proxy's base from the beat's scripted path,
//      times `off_area_factor` outside the play area;
//   S  steadiness: exp(−(r/r_0)²), r the RMS of the horizontal position's high-frequency residual
//      (tremor) over the window;
//   E  expression: the beat's characteristic feature measured on the trajectory over a window of
//      ±`window` s (step or hop height, sway tilt, head-turn range, tilt reached by a fall, heading
//      after a turn, contact of a hit) against the script's target, exp(−ln(m/target)²/2σ_e²);
//   M  motion: for travelling beats the speed ratio against the script's nominal speed
//      (exp(−ln²/2σ_v²)) times the agreement of the direction of travel with the script's
//      ((1 + cos)/2); for in-place beats stillness exp(−(v/v_0)²) (turns and head turns excepted).
//
// See docs/people.md for the reasons and every parameter.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "core/trajectory.h"
#include "people/story.h"

namespace mmh::people {

// Config section "performance.quality".
struct QualityOptions {
  double window = 0.6;              // [s] half width of the feature window
  double path_sigma = 0.02;         // [m] σ_p
  double off_area_factor = 0.3;     // P's factor outside the play area
  double play_area_width = 0.40;    // [m] as the table's (core/table_setup.h)
  double play_area_depth = 0.30;    // [m]
  double steadiness_scale = 0.003;  // [m] r_0
  double steadiness_weight = 0.5;   // w_s
  double feature_log_sd = 0.5;      // σ_e
  double speed_log_sd = 0.6;        // σ_v
  double stillness_speed = 0.03;    // [m/s] v_0
  double hit_sigma = 0.015;         // [m] contact error scale of a hit
  double kind_mismatch = 0.25;      // F for a beat other than the scripted one
  double expression_floor = 0.3;    // a: quality left when the expression is entirely off
  double motion_floor = 0.3;        // b

  template <class V>
  void VisitFields(V& v) {
    v("window", window);
    v("path_sigma", path_sigma);
    v("off_area_factor", off_area_factor);
    v("play_area_width", play_area_width);
    v("play_area_depth", play_area_depth);
    v("steadiness_scale", steadiness_scale);
    v("steadiness_weight", steadiness_weight);
    v("feature_log_sd", feature_log_sd);
    v("speed_log_sd", speed_log_sd);
    v("stillness_speed", stillness_speed);
    v("hit_sigma", hit_sigma);
    v("kind_mismatch", kind_mismatch);
    v("expression_floor", expression_floor);
    v("motion_floor", motion_floor);
  }
  void Validate(const std::string& prefix) const;
};

// Per-frame quality and its factors (each #frames, in [0, 1]).
struct QualityTrace {
  std::vector<double> quality;
  std::vector<double> fidelity, path, steadiness, expression, motion;
};

// A stretch of frames in which the animator performed one script beat with one action.
struct PerformedSegment {
  int script_beat = 0;
  BeatKind performed_kind = BeatKind::kStand;
  int first_frame = 0;  // inclusive
  int last_frame = 0;   // inclusive
};

struct QualityInputs {
  const StoryObject* object = nullptr;
  const Trajectory* table_T_proxy = nullptr;  // #frames
  double frame_rate = 30.0;
  std::vector<PerformedSegment> segments;  // in order, covering every frame once
  std::vector<double> script_progress;     // #frames: the animator's progress in the script
                                           // beat, 0 at its start, 1 at its end
  // Per script beat: where a hit beat must land (the target's top, table frame), if known.
  std::vector<std::optional<Eigen::Vector3d>> hit_targets;
};

QualityTrace ComputeTakeQuality(const QualityInputs& inputs, const QualityOptions& options);

// Angle of the proxy's z axis from the table's vertical [rad].
double TiltFromUpright(const Eigen::Quaterniond& table_R_proxy);
// Heading of the figure [rad]: direction its front (−y of the proxy frame) faces in the table's
// x-y plane.
double FacingHeading(const Eigen::Quaterniond& table_R_proxy);

}  // namespace mmh::people
