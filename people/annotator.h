// The animator annotating a take (paper, "Annotating the Takes"): while the take plays back, their
// judgement follows the latent quality seen through their own taste and noise, and their hand
// moves the green block in the Like box. The block's position per frame is what the sensor renders
// (sim/render_session.h), so the tracker must read it off the frames like the real system did.
//
// Model (docs/people.md):
//   judgement  j(t) = 5·tanh(g·(q(t) − θ)/5) + σ_o·n(t), n an AR(1) process of unit variance and
//                     time constant τ_o (a slowly drifting opinion);
//   target     r(t) = j(t − d(t)), the reaction delay d(t) = d̄ + δ·w(t) varying slowly
//                     (w in [−1, 1]); held during lapses of attention (Poisson, rate λ), and
//                     held while |j(t − d(t)) − r| ≤ h: the hand moves the block only when the
//                     opinion has left it by more than h (intermittent control: people correct
//                     in discrete moves, not continuously; Craik 1947, Loram et al. 2011). With
//                     h > 0 the block dwells at a few positions, the paper's "three discrete
//                     levels" on "a continuous scale";
//   hand       x'' = ω²(r − x) − 2ω·x' (critically damped: smooth, no overshoot), |x'| ≤ v_max,
//                     end stops at ±5, plus tremor; its lag at low frequencies is 2/ω.
// So the slider lags the judgement by about d̄ + 2/ω (0.3 s + 0.1 s at the defaults; the paper's
// system shifts annotations back by 0.3 s).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/annotation.h"
#include "core/cross_correlation.h"

namespace mmh::people {

// One annotator (the judging half of a simulated participant).
struct AnnotatorProfile {
  double reaction_delay = 0.30;   // [s] d̄
  double delay_variation = 0.03;  // [s] δ: the delay wanders within d̄ ± δ
  double taste_threshold = 0.5;   // θ: the quality they find neither good nor bad
  double taste_gain = 10.0;       // g [slider units per unit quality]
  double opinion_noise = 0.6;     // σ_o [slider units]
  double hand_frequency = 20.0;   // ω [rad/s]
  double max_speed = 25.0;        // v_max [slider units/s] (the Like box is 16 cm for 10 units)
  double tremor = 0.05;           // [slider units] RMS hand tremor on the block
  double lapse_rate = 1.0;        // λ [lapses per minute]
  double lapse_seconds = 1.5;     // [s] mean length of a lapse
  double move_threshold = 0.0;    // h [slider units]: opinion change that makes the hand move

  template <class V>
  void VisitFields(V& v) {
    v("reaction_delay", reaction_delay);
    v("delay_variation", delay_variation);
    v("taste_threshold", taste_threshold);
    v("taste_gain", taste_gain);
    v("opinion_noise", opinion_noise);
    v("hand_frequency", hand_frequency);
    v("max_speed", max_speed);
    v("tremor", tremor);
    v("lapse_rate", lapse_rate);
    v("lapse_seconds", lapse_seconds);
    v("move_threshold", move_threshold);
  }
  void Validate(const std::string& prefix) const;
};

// Config section "annotator": constants of the model shared by every annotator.
struct AnnotatorOptions {
  double frame_rate = 30.0;             // [Hz] playback rate
  double opinion_time_constant = 1.5;   // τ_o [s]
  double delay_wander_frequency = 0.1;  // [Hz] how fast the reaction delay wanders
  double start_value = 0.0;             // where the block rests when playback starts
  int substeps = 8;                     // integration steps of the hand per frame

  template <class V>
  void VisitFields(V& v) {
    v("frame_rate", frame_rate);
    v("opinion_time_constant", opinion_time_constant);
    v("delay_wander_frequency", delay_wander_frequency);
    v("start_value", start_value);
    v("substeps", substeps);
  }
  void Validate(const std::string& prefix) const;
};

struct AnnotationSession {
  std::vector<double> judgement;  // #frames: opinion of frame t, in [−5, 5] (before the delay)
  std::vector<double> delay;      // #frames: reaction delay at frame t [s]
  std::vector<double> slider;     // #frames: the block's true slider value in [−5, 5]
  std::vector<std::pair<int, int>> lapses;  // frames [first, last] of each lapse
  double clipped_fraction = 0.0;            // share of frames with the block at an end stop

  // The block's values as an annotation (timestamps i / frame_rate).
  Annotation SliderAnnotation(double frame_rate) const;
};

// Annotates a take whose latent quality per frame is `quality` (#frames, in [0, 1]).
// Deterministic in `seed`.
AnnotationSession AnnotateTake(std::span<const double> quality, const AnnotatorProfile& profile,
                               const AnnotatorOptions& options, std::uint64_t seed);

// CrossCorrelationLag (core/cross_correlation.h) estimates a session's lag.
using mmh::CrossCorrelationLag;

}  // namespace mmh::people
