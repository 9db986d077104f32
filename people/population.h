// Simulated participants: each draws an animator (people/performance.h) and an annotator
// (people/annotator.h) from the population's distributions. Deterministic in (seed, index), so that
// participant 7 is the same person whatever else is simulated.
#pragma once

#include <cstdint>
#include <string>

#include "people/annotator.h"
#include "people/performance.h"

namespace mmh::people {

// Config section "population". Normal distributions truncated to each field's range.
struct PopulationOptions {
  std::uint64_t seed = 1;    // the population's seed (participant i is DeriveSeed(seed, i))
  double skill_mean = 0.45;  // the paper's animators had no animation experience
  double skill_sd = 0.2;
  double energy_mean = 0.5;
  double energy_sd = 0.2;
  double learning_mean = 0.124;  // calibrated (docs/calibration.md), as move_threshold_mean
  double learning_sd = 0.1;
  double style_sd = 0.2;     // log-sd of the personal style multipliers
  double delay_mean = 0.30;  // [s] reaction delay, kept within [0.25, 0.35]
  double delay_sd = 0.025;
  double delay_variation = 0.02;  // [s] within-session wander of the delay
  double taste_threshold_mean = 0.5;
  double taste_threshold_sd = 0.08;
  double taste_gain_mean = 10.0;
  double taste_gain_sd = 3.0;
  double opinion_noise_mean = 0.6;
  double opinion_noise_sd = 0.2;
  double lapse_rate = 1.0;  // [1/min]
  // The annotators' dead band h (people/annotator.h), normal truncated at 0 [slider units].
  double move_threshold_mean = 1.40;
  double move_threshold_sd = 0.0;

  template <class V>
  void VisitFields(V& v) {
    v("seed", seed);
    v("skill_mean", skill_mean);
    v("skill_sd", skill_sd);
    v("energy_mean", energy_mean);
    v("energy_sd", energy_sd);
    v("learning_mean", learning_mean);
    v("learning_sd", learning_sd);
    v("style_sd", style_sd);
    v("delay_mean", delay_mean);
    v("delay_sd", delay_sd);
    v("delay_variation", delay_variation);
    v("taste_threshold_mean", taste_threshold_mean);
    v("taste_threshold_sd", taste_threshold_sd);
    v("taste_gain_mean", taste_gain_mean);
    v("taste_gain_sd", taste_gain_sd);
    v("opinion_noise_mean", opinion_noise_mean);
    v("opinion_noise_sd", opinion_noise_sd);
    v("lapse_rate", lapse_rate);
    v("move_threshold_mean", move_threshold_mean);
    v("move_threshold_sd", move_threshold_sd);
  }
  void Validate(const std::string& prefix) const;
};

struct Participant {
  int index = 0;
  AnimatorProfile animator;
  AnnotatorProfile annotator;
};

Participant DrawParticipant(const PopulationOptions& population, int index);

// The seed of everything participant `index` does (takes, annotations): independent streams.
std::uint64_t ParticipantSeed(const PopulationOptions& population, int index);

}  // namespace mmh::people
