#include "people/annotator.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/error.h"
#include "people/random.h"

namespace mmh::people {
namespace {

constexpr double kSliderLimit = 5.0;

// Value of `values` at fractional frame f (linear interpolation, clamped to the ends).
double Sample(const std::vector<double>& values, double f) {
  if (f <= 0) return values.front();
  const double last = static_cast<double>(values.size() - 1);
  if (f >= last) return values.back();
  const int i = static_cast<int>(f);
  const double w = f - i;
  return values[i] * (1 - w) + values[i + 1] * w;
}

}  // namespace

void AnnotatorProfile::Validate(const std::string& prefix) const {
  RequirePositive(reaction_delay, prefix + ".reaction_delay", "s");
  RequireNonNegative(delay_variation, prefix + ".delay_variation", "s");
  if (delay_variation >= reaction_delay) {
    ThrowBadValue(prefix + ".delay_variation", FormatNumber(delay_variation),
                  "less than reaction_delay (" + FormatNumber(reaction_delay) + " s)");
  }
  if (reaction_delay > 3.0) {
    ThrowBadValue(prefix + ".reaction_delay", FormatNumber(reaction_delay), "at most 3 s");
  }
  RequireProbability(taste_threshold, prefix + ".taste_threshold");
  RequirePositive(taste_gain, prefix + ".taste_gain");
  RequireNonNegative(opinion_noise, prefix + ".opinion_noise");
  RequirePositive(hand_frequency, prefix + ".hand_frequency", "rad/s");
  RequirePositive(max_speed, prefix + ".max_speed", "slider units/s");
  RequireNonNegative(tremor, prefix + ".tremor");
  RequireNonNegative(lapse_rate, prefix + ".lapse_rate", "1/min");
  RequireFinite(move_threshold, prefix + ".move_threshold");
  if (!(move_threshold >= 0.0 && move_threshold <= 2 * kSliderLimit)) {
    ThrowBadValue(prefix + ".move_threshold", FormatNumber(move_threshold),
                  "a slider distance in [0, 10]");
  }
  RequirePositive(lapse_seconds, prefix + ".lapse_seconds", "s");
}

void AnnotatorOptions::Validate(const std::string& prefix) const {
  if (!(frame_rate >= 1 && frame_rate <= 1000)) {
    ThrowBadValue(prefix + ".frame_rate", FormatNumber(frame_rate), "a rate in [1, 1000] Hz");
  }
  RequirePositive(opinion_time_constant, prefix + ".opinion_time_constant", "s");
  RequirePositive(delay_wander_frequency, prefix + ".delay_wander_frequency", "Hz");
  if (!(std::abs(start_value) <= kSliderLimit)) {
    ThrowBadValue(prefix + ".start_value", FormatNumber(start_value), "a slider value in [-5, 5]");
  }
  if (substeps < 1 || substeps > 1000) {
    ThrowBadValue(prefix + ".substeps", std::to_string(substeps), "an integer in [1, 1000]");
  }
}

Annotation AnnotationSession::SliderAnnotation(double frame_rate) const {
  Annotation annotation;
  for (std::size_t i = 0; i < slider.size(); ++i) {
    annotation.timestamps.push_back(i / frame_rate);
    annotation.values.push_back(slider[i]);
  }
  return annotation;
}

AnnotationSession AnnotateTake(std::span<const double> quality, const AnnotatorProfile& profile,
                               const AnnotatorOptions& options, std::uint64_t seed) {
  profile.Validate("annotator profile");
  options.Validate("annotator");
  const int n = static_cast<int>(quality.size());
  AnnotationSession session;
  if (n == 0) return session;
  for (int i = 0; i < n; ++i) {
    if (!(quality[i] >= 0.0 && quality[i] <= 1.0)) {
      ThrowBadValue("quality[" + std::to_string(i) + "]", FormatNumber(quality[i]),
                    "a latent quality in [0, 1]");
    }
  }
  const double fps = options.frame_rate;
  const double dt = 1.0 / fps;
  Random random(DeriveSeed(seed, {0xa770ull}));

  // Judgement: taste through a soft saturation, plus a slowly drifting opinion (AR(1)).
  session.judgement.resize(n);
  // What the hand aims at: beyond an end of the box when the opinion is beyond it (the block is
  // pushed against the end stop).
  std::vector<double> aim(n);
  const double rho = std::exp(-dt / options.opinion_time_constant);
  double opinion = random.Normal();
  for (int i = 0; i < n; ++i) {
    if (i > 0) opinion = rho * opinion + std::sqrt(1 - rho * rho) * random.Normal();
    const double j =
        kSliderLimit *
            std::tanh(profile.taste_gain * (quality[i] - profile.taste_threshold) / kSliderLimit) +
        profile.opinion_noise * opinion;
    aim[i] = j;
    session.judgement[i] = std::clamp(j, -kSliderLimit, kSliderLimit);
  }

  // Reaction delay wandering within d̄ ± δ (a sum of slow sinusoids, normalised to [−1, 1]).
  double frequency[3], phase[3];
  for (int k = 0; k < 3; ++k) {
    frequency[k] = options.delay_wander_frequency * random.Uniform(0.5, 1.5);
    phase[k] = random.Uniform(0, 2 * std::numbers::pi);
  }
  session.delay.resize(n);
  for (int i = 0; i < n; ++i) {
    double w = 0;
    for (int k = 0; k < 3; ++k)
      w += std::sin(2 * std::numbers::pi * frequency[k] * i * dt + phase[k]);
    session.delay[i] = profile.reaction_delay + profile.delay_variation * w / 3;
  }

  // Lapses of attention: Poisson starts, exponential lengths; the hand holds still.
  std::vector<char> lapsed(n, 0);
  if (profile.lapse_rate > 0) {
    double t = random.Exponential(60.0 / profile.lapse_rate);
    while (t < n * dt) {
      const double length = std::max(random.Exponential(profile.lapse_seconds), 2 * dt);
      const int first = static_cast<int>(std::ceil(t * fps));
      const int last = std::min(n - 1, static_cast<int>((t + length) * fps));
      if (first <= last) {
        session.lapses.push_back({first, last});
        for (int i = first; i <= last; ++i) lapsed[i] = 1;
      }
      t += length + random.Exponential(60.0 / profile.lapse_rate);
    }
  }

  // Hand tremor: a sum of 8-12 Hz sinusoids of the given RMS.
  double tremor_frequency[2], tremor_phase[2];
  for (int k = 0; k < 2; ++k) {
    tremor_frequency[k] = random.Uniform(8.0, 12.0);
    tremor_phase[k] = random.Uniform(0, 2 * std::numbers::pi);
  }

  // The hand: critically damped pursuit of the delayed judgement, speed-limited, end stops.
  session.slider.resize(n);
  const double omega = profile.hand_frequency;
  const double h = dt / options.substeps;
  double x = options.start_value, v = 0, target = options.start_value;
  int clipped = 0;
  for (int i = 0; i < n; ++i) {
    if (!lapsed[i]) {
      const double seen = i - session.delay[i] * fps;  // the frame whose judgement arrives now
      const double wanted = seen < 0 ? options.start_value : Sample(aim, seen);
      if (std::abs(wanted - target) > profile.move_threshold) target = wanted;
    }
    for (int s = 0; s < options.substeps; ++s) {
      // Semi-implicit Euler: stable for ω·h << 1 (h = 4 ms at the defaults).
      v += h * (omega * omega * (target - x) - 2 * omega * v);
      v = std::clamp(v, -profile.max_speed, profile.max_speed);
      x += h * v;
      if (std::abs(x) >= kSliderLimit) {
        x = std::clamp(x, -kSliderLimit, kSliderLimit);
        v = 0;
      }
    }
    double tremor = 0;
    for (int k = 0; k < 2; ++k) {
      tremor += std::sin(2 * std::numbers::pi * tremor_frequency[k] * i * dt + tremor_phase[k]);
    }
    const double value = std::clamp(x + profile.tremor * tremor, -kSliderLimit, kSliderLimit);
    if (std::abs(value) >= kSliderLimit) ++clipped;
    session.slider[i] = value;
  }
  session.clipped_fraction = static_cast<double>(clipped) / n;
  return session;
}

}  // namespace mmh::people
