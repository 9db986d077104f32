// Animators and their takes: a story (people/story.h) acted out with a proxy at 30 fps, take after
// take. A take has its own timing (takes differ in length), the animator's style in every beat,
// hand tremor and localised flaws; every frame carries the ground-truth pose and a latent quality
// measured from the performance itself (people/take_quality.h). The model is the harness's
// hypothesis, documented in docs/people.md with every parameter.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/trajectory.h"
#include "people/story.h"
#include "people/take_quality.h"

namespace mmh::people {

// Who acts (the performer half of a simulated participant).
struct AnimatorProfile {
  double skill = 0.5;     // [0, 1] at the first take: precision of timing, path and style, flaws
  double energy = 0.5;    // [0, 1] tempo and amplitude of the performance (0.5 = as scripted)
  double learning = 0.3;  // [0, 1] share of the remaining gap to skill 1 closed per take
  // The animator's own style: multipliers of the script's targets (1 = as scripted).
  double bounce_style = 1.0;  // step and hop heights
  double sway_style = 1.0;    // side-to-side sway
  double yaw_style = 1.0;     // head turns
  double tempo_style = 1.0;   // step rate

  template <class V>
  void VisitFields(V& v) {
    v("skill", skill);
    v("energy", energy);
    v("learning", learning);
    v("bounce_style", bounce_style);
    v("sway_style", sway_style);
    v("yaw_style", yaw_style);
    v("tempo_style", tempo_style);
  }
  // Skill at take k (0-based): 1 - (1 - skill)(1 - learning)^k; the paper's animators ranked
  // later takes higher.
  double SkillAtTake(int take) const;
  void Validate(const std::string& prefix) const;
};

enum class FlawKind {
  kHesitation,      // stops for a moment in the middle of a beat
  kOutOfOrder,      // performs this beat and the next in swapped order
  kMissed,          // skips the beat (carries on with the previous action, hurried)
  kWrongDirection,  // sets off the wrong way (a round the other way round)
  kBotchedFall,     // the fall does not go down
  kOffArea,         // a stretch that leaves the play area
};
std::span<const std::pair<FlawKind, const char*>> EnumNames(FlawKind);

struct Flaw {
  FlawKind kind = FlawKind::kHesitation;
  int beat = 0;         // the script beat it spoils
  int first_frame = 0;  // frames of the take it affects, inclusive
  int last_frame = 0;
};

// Config section "performance". Rates and spreads are given for an unskilled (skill 0) and a
// perfect (skill 1) animator and interpolated linearly in skill.
struct PerformanceOptions {
  double frame_rate = 30.0;           // [Hz] the Kinect's
  double timing_sd_unskilled = 0.30;  // log-sd of a beat's duration
  double timing_sd_skilled = 0.04;
  double amplitude_sd_unskilled = 0.45;  // log-sd of a beat's style amplitudes around the target
  double amplitude_sd_skilled = 0.08;
  double take_style_sd = 0.15;       // log-sd of the per-take style change (animators were
                                     // encouraged to try different styles on each take)
  double tremor_unskilled = 0.0035;  // [m] hand tremor amplitude (6-11 Hz)
  double tremor_skilled = 0.0004;
  double tremor_angle = 6.0;        // [rad/m] rotational tremor per metre of positional
  double wander_unskilled = 0.018;  // [m] slow sideways deviation from the path (0.1-0.4 Hz)
  double wander_skilled = 0.002;
  // Flaw probabilities per beat at skill 0 (scaled by 1 - skill).
  double hesitation_rate = 0.22;
  double out_of_order_rate = 0.06;
  double missed_rate = 0.05;
  double wrong_direction_rate = 0.08;   // travelling beats only
  double botched_fall_rate = 0.6;       // fall beats only
  double off_area_rate = 0.08;          // travelling beats only
  double hesitation_seconds = 1.2;      // [s] mean pause of a hesitation
  double heading_time_constant = 0.12;  // [s] the figure turns towards where it walks
  QualityOptions quality;               // how the latent quality is measured

  template <class V>
  void VisitFields(V& v) {
    v("frame_rate", frame_rate);
    v("timing_sd_unskilled", timing_sd_unskilled);
    v("timing_sd_skilled", timing_sd_skilled);
    v("amplitude_sd_unskilled", amplitude_sd_unskilled);
    v("amplitude_sd_skilled", amplitude_sd_skilled);
    v("take_style_sd", take_style_sd);
    v("tremor_unskilled", tremor_unskilled);
    v("tremor_skilled", tremor_skilled);
    v("tremor_angle", tremor_angle);
    v("wander_unskilled", wander_unskilled);
    v("wander_skilled", wander_skilled);
    v("hesitation_rate", hesitation_rate);
    v("out_of_order_rate", out_of_order_rate);
    v("missed_rate", missed_rate);
    v("wrong_direction_rate", wrong_direction_rate);
    v("botched_fall_rate", botched_fall_rate);
    v("off_area_rate", off_area_rate);
    v("hesitation_seconds", hesitation_seconds);
    v("heading_time_constant", heading_time_constant);
    v("quality", quality);
  }
  void Validate(const std::string& prefix) const;
};

// One take of one object.
struct PerformedTake {
  int take = 0;                          // 0-based take index
  int object = 0;                        // index of the object in the story
  double skill = 0.0;                    // the animator's skill at this take
  Trajectory table_T_proxy;              // #frames poses, timestamps i / frame_rate
  std::vector<int> script_beat;          // #frames: the script beat being performed
  std::vector<BeatKind> performed_kind;  // #frames: what the animator actually did
  std::vector<double> script_progress;   // #frames: progress in the script beat, 0..1
  std::vector<std::optional<Eigen::Vector3d>> hit_targets;  // per script beat: where a hit lands
  QualityTrace quality;  // #frames latent quality and its factors
  std::vector<Flaw> flaws;
  std::vector<int> markers;  // layered takes: spatial marker frames (montage timeline)

  int frames() const { return static_cast<int>(table_T_proxy.poses.size()); }
  double MeanQuality() const;
};

// The latent quality of `motion` (#frames table_T_proxy, e.g. a tracked or edited version of the
// take) performed as `take` was (same beats, progress and hit targets).
QualityTrace MeasureQuality(const StoryObject& object, const PerformedTake& take,
                            const Trajectory& motion, const QualityOptions& options,
                            double frame_rate);

// Performs take `take` of `story.objects[object]`. Deterministic in (seed, take, object).
// Throws InputError for a layered object (one with hit beats): use PerformLayeredTake.
PerformedTake PerformTake(const Story& story, int object, const AnimatorProfile& animator, int take,
                          const PerformanceOptions& options, std::uint64_t seed);

// Layered recording (paper, "Layered animations"): the take of `story.objects[object]` is recorded
// while the earlier objects' montages play, so it has their length (`frames`), and its hit beats
// aim at the target's pose in `earlier_montages[target]` (table_T_proxy, #frames each; entries of
// objects that are not targets may be empty). Before recording, the animator places a spatial
// marker at each interaction beat (the paper's Figure 5), at least `min_marker_gap` frames apart;
// the take's hits aim at those frames.
PerformedTake PerformLayeredTake(const Story& story, int object, const AnimatorProfile& animator,
                                 int take, int frames, std::span<const Trajectory> earlier_montages,
                                 const PerformanceOptions& options, std::uint64_t seed,
                                 int min_marker_gap = 60);

}  // namespace mmh::people
