#include "people/population.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "people/random.h"

namespace mmh::people {

void PopulationOptions::Validate(const std::string& prefix) const {
  for (const auto& [mean, name] : {std::pair{skill_mean, "skill_mean"},
                                   {energy_mean, "energy_mean"},
                                   {learning_mean, "learning_mean"},
                                   {taste_threshold_mean, "taste_threshold_mean"}}) {
    RequireProbability(mean, prefix + "." + name);
  }
  for (const auto& [sd, name] : {std::pair{skill_sd, "skill_sd"},
                                 {energy_sd, "energy_sd"},
                                 {learning_sd, "learning_sd"},
                                 {style_sd, "style_sd"},
                                 {delay_sd, "delay_sd"},
                                 {delay_variation, "delay_variation"},
                                 {taste_threshold_sd, "taste_threshold_sd"},
                                 {taste_gain_sd, "taste_gain_sd"},
                                 {opinion_noise_sd, "opinion_noise_sd"},
                                 {opinion_noise_mean, "opinion_noise_mean"},
                                 {lapse_rate, "lapse_rate"},
                                 {move_threshold_mean, "move_threshold_mean"},
                                 {move_threshold_sd, "move_threshold_sd"}}) {
    RequireNonNegative(sd, prefix + "." + name);
  }
  if (!(delay_mean >= 0.25 && delay_mean <= 0.35)) {
    ThrowBadValue(prefix + ".delay_mean", FormatNumber(delay_mean),
                  "a reaction delay in [0.25, 0.35] s (human reaction plus block movement)");
  }
  if (delay_variation >= 0.25) {
    ThrowBadValue(prefix + ".delay_variation", FormatNumber(delay_variation), "less than 0.25 s");
  }
  RequirePositive(taste_gain_mean, prefix + ".taste_gain_mean");
}

std::uint64_t ParticipantSeed(const PopulationOptions& population, int index) {
  return DeriveSeed(population.seed, {0x7061ull, static_cast<std::uint64_t>(index)});
}

Participant DrawParticipant(const PopulationOptions& p, int index) {
  p.Validate("population");
  Random random(DeriveSeed(p.seed, {0x7065ull, static_cast<std::uint64_t>(index)}));
  Participant participant;
  participant.index = index;
  AnimatorProfile& a = participant.animator;
  a.skill = std::clamp(random.Normal(p.skill_mean, p.skill_sd), 0.02, 0.98);
  a.energy = std::clamp(random.Normal(p.energy_mean, p.energy_sd), 0.0, 1.0);
  a.learning = std::clamp(random.Normal(p.learning_mean, p.learning_sd), 0.0, 0.9);
  a.bounce_style = std::exp(random.Normal(0, p.style_sd));
  a.sway_style = std::exp(random.Normal(0, p.style_sd));
  a.yaw_style = std::exp(random.Normal(0, p.style_sd));
  a.tempo_style = std::exp(random.Normal(0, 0.5 * p.style_sd));
  AnnotatorProfile& n = participant.annotator;
  n.reaction_delay = std::clamp(random.Normal(p.delay_mean, p.delay_sd), 0.25, 0.35);
  n.delay_variation = std::min(p.delay_variation, 0.5 * n.reaction_delay);
  n.taste_threshold =
      std::clamp(random.Normal(p.taste_threshold_mean, p.taste_threshold_sd), 0.05, 0.95);
  n.taste_gain = std::max(1.0, random.Normal(p.taste_gain_mean, p.taste_gain_sd));
  n.opinion_noise = std::max(0.0, random.Normal(p.opinion_noise_mean, p.opinion_noise_sd));
  n.lapse_rate = p.lapse_rate;
  // Drawn last, so that adding it left every earlier draw (and participant) as it was.
  n.move_threshold = std::clamp(random.Normal(p.move_threshold_mean, p.move_threshold_sd), 0.0,
                                10.0);  // the box spans 10 slider units
  return participant;
}

}  // namespace mmh::people
