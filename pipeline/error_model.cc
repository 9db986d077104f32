#include "pipeline/error_model.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "core/options.h"
#include "people/random.h"

namespace mmh::pipeline {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Random streams of one simulated take, so that changing one part of the model leaves the draws
// of the others alone.
enum Stream : std::uint64_t {
  kPoseStream = 1,
  kFlipStream,
  kLossStream,
  kSliderStream,
  kSpikeStream,
  kFlipShapeStream,
  kSpikeShapeStream,
  kSlowStream,
  kFlipLostStream
};

void RequireCorrelation(double value, const std::string& where) {
  RequireFinite(value, where);
  if (value < 0.0 || value >= 1.0) ThrowBadValue(where, FormatNumber(value), "a value in [0, 1)");
}

void RequireEpisodeLength(double value, const std::string& where) {
  RequireFinite(value, where);
  if (value < 1.0) ThrowBadValue(where, FormatNumber(value), "a mean length of at least 1 frame");
}

// A stationary AR(1) process with standard deviation `sd` and lag-one correlation `rho`.
class Ar1 {
 public:
  Ar1(double sd, double rho) : sd_(sd), rho_(rho), innovation_(std::sqrt(1.0 - rho * rho)) {}
  double Next(people::Random& random) {
    x_ = started_ ? rho_ * x_ + innovation_ * sd_ * random.Normal() : sd_ * random.Normal();
    started_ = true;
    return x_;
  }

 private:
  double sd_, rho_, innovation_;
  double x_ = 0.0;
  bool started_ = false;
};

// The core error of one axis (the header's x_t = s_t + f_t): the fast jitter f from `random`, the
// slow drift s from `slow_random` (not drawn where w = 0, so that the single AR(1) keeps its draws).
class Core {
 public:
  Core(double sd, double correlation, double slow_share, double slow_correlation)
      : fast_(sd * std::sqrt(1.0 - slow_share), correlation),
        slow_(sd * std::sqrt(slow_share), slow_correlation),
        has_slow_(slow_share > 0) {}
  double Next(people::Random& random, people::Random& slow_random) {
    const double fast = fast_.Next(random);
    return has_slow_ ? fast + slow_.Next(slow_random) : fast;
  }

 private:
  Ar1 fast_, slow_;
  bool has_slow_;
};

// The six axes' cores of `options`-like sds and time scales: rotation x3, translation x3.
template <class T>
std::array<Core, 6> CoreAxes(const T& m) {
  const auto axis = [&](double sd) {
    return Core(sd, m.correlation, m.slow_share, m.slow_correlation);
  };
  return {axis(m.rotation_sd),    axis(m.rotation_sd),    axis(m.rotation_sd),
          axis(m.translation_sd), axis(m.translation_sd), axis(m.translation_sd)};
}

// Episodes of one kind on `frames` frames: an episode starts at a free frame t with probability
// rate(c[t]) and ends after each of its frames u with probability 1 / mean_frames(c[u]) (the
// hazards of `rates[c].*member`, see the header). The episode's number (0, 1, ...) for each of its
// frames, -1 elsewhere. Frames already in `busy` (>= 0) neither start nor extend an episode.
std::vector<int> DrawEpisodes(const std::vector<int>& condition, const ViewRates& view,
                              double EpisodeRates::*rate, double EpisodeRates::*mean_frames,
                              const std::vector<int>& busy, std::uint64_t seed) {
  const int frames = static_cast<int>(condition.size());
  std::vector<int> episode(frames, -1);
  people::Random random(seed);
  int count = 0;
  bool in_episode = false;
  for (int t = 0; t < frames; ++t) {
    if (busy[t] >= 0) {
      in_episode = false;
      continue;
    }
    const EpisodeRates& rates = view.condition[condition[t]];
    if (!in_episode) {
      if (!random.Bernoulli(rates.*rate)) continue;
      in_episode = true;
      ++count;
    }
    episode[t] = count - 1;
    if (random.Bernoulli(1.0 / (rates.*mean_frames))) in_episode = false;
  }
  return episode;
}

// Frames in either set of episodes (>= 0 in one of them).
std::vector<int> Union(const std::vector<int>& a, const std::vector<int>& b) {
  std::vector<int> out(a.size());
  for (std::size_t t = 0; t < a.size(); ++t) out[t] = std::max(a[t], b[t]);
  return out;
}

Eigen::Quaterniond ExpRotation(const Eigen::Vector3d& r) {
  const double angle = r.norm();
  return angle > 0 ? Eigen::Quaterniond(Eigen::AngleAxisd(angle, r / angle))
                   : Eigen::Quaterniond::Identity();
}

// Runs of true values per view condition: runs starting in it, frames free to start one (not in a
// run and not excluded, plus the run starts), run frames in it and runs ending after one of them
// (not counting a run cut by the end of the take).
struct Runs {
  std::array<std::int64_t, kViewConditions> starts{}, at_risk{}, frames{}, ends{};
  std::int64_t Total(const std::array<std::int64_t, kViewConditions>& per) const {
    std::int64_t sum = 0;
    for (const std::int64_t n : per) sum += n;
    return sum;
  }
};
void CountRuns(const std::vector<bool>& flag, const std::vector<bool>& excluded,
               const std::vector<int>& condition, Runs* runs) {
  const std::size_t n = flag.size();
  for (std::size_t t = 0; t < n; ++t) {
    const int c = condition[t];
    if (flag[t]) {
      ++runs->frames[c];
      if (t == 0 || !flag[t - 1]) ++runs->starts[c], ++runs->at_risk[c];
      if (t + 1 < n && !flag[t + 1]) ++runs->ends[c];
    } else if (!excluded[t]) {
      ++runs->at_risk[c];
    }
  }
}

// The hazards of one kind from its runs, per condition with data (the others keep the prior's).
void FitHazards(const Runs& runs, double EpisodeRates::*rate, double EpisodeRates::*mean_frames,
                ViewRates* view) {
  for (int c = 0; c < kViewConditions; ++c) {
    EpisodeRates& r = view->condition[c];
    if (runs.at_risk[c] > 0) {
      r.*rate = static_cast<double>(runs.starts[c]) / static_cast<double>(runs.at_risk[c]);
    }
    if (runs.ends[c] > 0) {
      r.*mean_frames = static_cast<double>(runs.frames[c]) / static_cast<double>(runs.ends[c]);
    }
  }
}

std::string Number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", value);
  return buffer;
}

}  // namespace

const char* ViewConditionName(int condition) {
  static constexpr const char* kNames[kViewConditions] = {
      "heading_000", "heading_030", "heading_060", "heading_090", "heading_120",
      "heading_150", "heading_180", "heading_210", "heading_240", "heading_270",
      "heading_300", "heading_330", "lying"};
  if (condition < 0 || condition >= kViewConditions) {
    ThrowBadValue("view condition", std::to_string(condition),
                  "0.." + std::to_string(kViewConditions - 1));
  }
  return kNames[condition];
}

ViewRates ViewRates::Uniform(const EpisodeRates& rates) {
  ViewRates view;
  view.condition.fill(rates);
  return view;
}

void EpisodeRates::Validate(const std::string& prefix) const {
  RequireProbability(loss_rate, prefix + ".loss_rate");
  RequireEpisodeLength(loss_mean_frames, prefix + ".loss_mean_frames");
  RequireProbability(flip_rate, prefix + ".flip_rate");
  RequireEpisodeLength(flip_mean_frames, prefix + ".flip_mean_frames");
  RequireProbability(spike_rate, prefix + ".spike_rate");
  RequireEpisodeLength(spike_mean_frames, prefix + ".spike_mean_frames");
}

int ViewCondition(const Rigid3& table_T_proxy, const Eigen::Vector3d& table_camera_position,
                  double lying_tilt_deg) {
  return ViewConditionOf(ProxyHeadingDeg(table_T_proxy, table_camera_position),
                         ProxyTiltDeg(table_T_proxy), lying_tilt_deg);
}

int ViewConditionOf(double heading_deg, double tilt_deg, double lying_tilt_deg) {
  if (tilt_deg > lying_tilt_deg) return kLying;
  return std::min(kHeadingSectors - 1, static_cast<int>(heading_deg / (360.0 / kHeadingSectors)));
}

void ErrorModelOptions::Validate(const std::string& prefix) const {
  RequireNonNegative(translation_sd, prefix + ".translation_sd", "m");
  RequireNonNegative(rotation_sd, prefix + ".rotation_sd", "rad");
  RequireCorrelation(correlation, prefix + ".correlation");
  RequireProbability(slow_share, prefix + ".slow_share");
  RequireCorrelation(slow_correlation, prefix + ".slow_correlation");
  RequireFinite(flip_rotation, prefix + ".flip_rotation");
  if (flip_rotation < 0 || flip_rotation > kPi) {
    ThrowBadValue(prefix + ".flip_rotation", FormatNumber(flip_rotation),
                  "an angle in [0, pi] rad");
  }
  RequireNonNegative(flip_translation, prefix + ".flip_translation", "m");
  RequireProbability(flip_lost_share, prefix + ".flip_lost_share");
  if (flip_lost_share >= 1.0) {
    ThrowBadValue(prefix + ".flip_lost_share", FormatNumber(flip_lost_share),
                  "a share below 1 (a flip shows its twin)");
  }
  RequireNonNegative(spike_rotation_sd, prefix + ".spike_rotation_sd", "rad");
  RequireNonNegative(spike_translation_sd, prefix + ".spike_translation_sd", "m");
  RequireFinite(lying_tilt_deg, prefix + ".lying_tilt_deg");
  if (lying_tilt_deg <= 0 || lying_tilt_deg > 180) {
    ThrowBadValue(prefix + ".lying_tilt_deg", FormatNumber(lying_tilt_deg),
                  "an angle in (0, 180] degrees");
  }
  for (int c = 0; c < kViewConditions; ++c) {
    view.condition[c].Validate(prefix + ".view." + ViewConditionName(c));
  }
  RequireNonNegative(slider_sd, prefix + ".slider_sd", "slider units");
  RequireCorrelation(slider_correlation, prefix + ".slider_correlation");
  RequireFinite(slider_bias, prefix + ".slider_bias");
  if (std::abs(slider_bias) > 10) {
    ThrowBadValue(prefix + ".slider_bias", FormatNumber(slider_bias),
                  "a bias within [-10, 10] slider units");
  }
  RequireProbability(slider_miss_share, prefix + ".slider_miss_share");
  if (slider_miss_share >= 1.0) {
    ThrowBadValue(prefix + ".slider_miss_share", FormatNumber(slider_miss_share),
                  "a share below 1 (some frames must be found)");
  }
}

SimulatedTracking SimulateTracking(const Trajectory& truth, const ErrorModelOptions& options,
                                   std::uint64_t seed,
                                   const Eigen::Vector3d& table_camera_position) {
  options.Validate("error_model");
  const int frames = static_cast<int>(truth.size());
  std::vector<int> condition(frames);
  for (int t = 0; t < frames; ++t) {
    condition[t] = ViewCondition(truth.poses[t], table_camera_position, options.lying_tilt_deg);
  }
  SimulatedTracking out;
  out.tracked.timestamps = truth.timestamps;
  out.tracked.poses.resize(frames);
  out.status.assign(frames, track::TrackStatus::kTracked);

  const std::vector<int> none(frames, -1);
  const ViewRates& view = options.view;
  const std::vector<int> flip =
      DrawEpisodes(condition, view, &EpisodeRates::flip_rate, &EpisodeRates::flip_mean_frames, none,
                   people::DeriveSeed(seed, {kFlipStream}));
  const std::vector<int> lost =
      DrawEpisodes(condition, view, &EpisodeRates::loss_rate, &EpisodeRates::loss_mean_frames, flip,
                   people::DeriveSeed(seed, {kLossStream}));
  // A flip's own lost frames (the tracker loses the proxy and finds the twin again).
  std::vector<bool> flip_lost(frames, false);
  people::Random flip_lost_random(people::DeriveSeed(seed, {kFlipLostStream}));
  for (int t = 0; t < frames; ++t) {
    if (flip[t] >= 0) flip_lost[t] = flip_lost_random.Bernoulli(options.flip_lost_share);
  }
  const std::vector<int> spike =
      DrawEpisodes(condition, view, &EpisodeRates::spike_rate, &EpisodeRates::spike_mean_frames,
                   Union(lost, flip), people::DeriveSeed(seed, {kSpikeStream}));

  people::Random random(people::DeriveSeed(seed, {kPoseStream}));
  people::Random slow_random(people::DeriveSeed(seed, {kSlowStream}));
  std::array<Core, 6> axes = CoreAxes(options);
  const Eigen::Quaterniond twin(Eigen::AngleAxisd(options.flip_rotation, Eigen::Vector3d::UnitZ()));
  // Each episode's shape: a flip's horizontal offset direction, a spike's error.
  people::Random flip_shape(people::DeriveSeed(seed, {kFlipShapeStream}));
  people::Random spike_shape(people::DeriveSeed(seed, {kSpikeShapeStream}));
  int flip_episode = -1, spike_episode = -1;
  Eigen::Vector3d flip_offset = Eigen::Vector3d::Zero();
  Eigen::Vector3d spike_r = Eigen::Vector3d::Zero(), spike_e = Eigen::Vector3d::Zero();
  for (int t = 0; t < frames; ++t) {
    // The error processes run on through the episodes (the tracker's bias drifts with the view
    // either way), so the draws of a frame do not depend on them.
    std::array<double, 6> x;
    for (int k = 0; k < 6; ++k) x[k] = axes[k].Next(random, slow_random);
    if (lost[t] >= 0 || flip_lost[t]) {
      out.status[t] = track::TrackStatus::kLost;
      out.tracked.poses[t] = t > 0 ? out.tracked.poses[t - 1] : truth.poses[t];
      continue;
    }
    Eigen::Vector3d r(x[0], x[1], x[2]), e(x[3], x[4], x[5]);
    if (spike[t] >= 0) {
      if (spike[t] != spike_episode) {
        spike_episode = spike[t];
        for (int k = 0; k < 3; ++k) spike_r[k] = spike_shape.Normal(0, options.spike_rotation_sd);
        for (int k = 0; k < 3; ++k) {
          spike_e[k] = spike_shape.Normal(0, options.spike_translation_sd);
        }
      }
      r += spike_r;
      e += spike_e;
    }
    Rigid3 table_T_tracked = truth.poses[t] * Rigid3(ExpRotation(r), e);
    if (flip[t] >= 0) {
      if (flip[t] != flip_episode) {
        flip_episode = flip[t];
        const double heading = flip_shape.Uniform(0, 2 * kPi);
        flip_offset =
            options.flip_translation * Eigen::Vector3d(std::cos(heading), std::sin(heading), 0.0);
      }
      // The near-symmetric twin: turned about the table's vertical, off by the offset.
      table_T_tracked.rotation = (twin * table_T_tracked.rotation).normalized();
      table_T_tracked.translation += flip_offset;
    }
    out.tracked.poses[t] = table_T_tracked;
  }
  return out;
}

SimulatedReading SimulateSliderReading(const Annotation& truth, const ErrorModelOptions& options,
                                       std::uint64_t seed) {
  options.Validate("error_model");
  const int frames = static_cast<int>(truth.size());
  SimulatedReading out;
  out.read.timestamps = truth.timestamps;
  out.read.values.assign(frames, 0.0);
  out.found.assign(frames, true);
  people::Random random(people::DeriveSeed(seed, {kSliderStream}));
  Ar1 noise(options.slider_sd, options.slider_correlation);
  int first_found = -1;
  for (int t = 0; t < frames; ++t) {
    const double n = noise.Next(random);
    out.found[t] = !random.Bernoulli(options.slider_miss_share);
    if (!out.found[t]) continue;
    out.read.values[t] =
        std::clamp(truth.values[t] + options.slider_bias + n, kMinAnnotation, kMaxAnnotation);
    if (first_found < 0) first_found = t;
  }
  // Hold the last found value; before the first found frame, the first found value (or the
  // truth's first value, clamped, when nothing is found at all).
  double held =
      first_found >= 0
          ? out.read.values[first_found]
          : (frames > 0 ? std::clamp(truth.values[0], kMinAnnotation, kMaxAnnotation) : 0.0);
  for (int t = 0; t < frames; ++t) {
    if (out.found[t]) {
      held = out.read.values[t];
    } else {
      out.read.values[t] = held;
    }
  }
  return out;
}

nlohmann::json ErrorModelEstimate::ToJson() const {
  nlohmann::json j = mmh::ToJson(options);
  return {{"options", j},
          {"frames", frames},
          {"inlier_frames", inlier_frames},
          {"flip_frames", flip_frames},
          {"spike_frames", spike_frames},
          {"lost_frames", lost_frames},
          {"flip_lost_frames", flip_lost_frames},
          {"flip_episodes", flip_episodes},
          {"spike_episodes", spike_episodes},
          {"moments", mmh::ToJson(moments)},
          {"core_excursion_rate", core_excursion_rate},
          {"core_autocorrelation", core_autocorrelation},
          {"spike_visibility", spike_visibility},
          {"simulation_iterations", simulation_iterations},
          {"corrected", corrected},
          {"loss_episodes", loss_episodes},
          {"slider_frames", slider_frames},
          {"slider_missed", slider_missed},
          {"slider_rmse", slider_rmse},
          {"condition_frames", condition_frames}};
}

std::string ErrorModelEstimate::DefaultsSource(const std::string& origin) const {
  const ErrorModelOptions& o = options;
  std::string out =
      "// The error model's measured defaults (pipeline/error_model.h), written by\n"
      "// ErrorModelEstimate::DefaultsSource; regenerate with a full-fidelity study "
      "(docs/study.md,\n"
      "// \"Fidelity\"). Measured on: " +
      origin + "\n// " + std::to_string(frames) + " tracked frames, " +
      std::to_string(flip_episodes) + " flips, " + std::to_string(spike_episodes) + " spikes, " +
      std::to_string(loss_episodes) + " losses.\n";
  const auto constant = [&](const char* name, double value) {
    out += std::string("inline constexpr double ") + name + " = " + Number(value) + ";\n";
  };
  constant("kTranslationSd", o.translation_sd);
  constant("kRotationSd", o.rotation_sd);
  constant("kCorrelation", o.correlation);
  constant("kSlowShare", o.slow_share);
  constant("kSlowCorrelation", o.slow_correlation);
  constant("kFlipRotation", o.flip_rotation);
  constant("kFlipTranslation", o.flip_translation);
  constant("kFlipLostShare", o.flip_lost_share);
  constant("kSpikeRotationSd", o.spike_rotation_sd);
  constant("kSpikeTranslationSd", o.spike_translation_sd);
  constant("kSliderSd", o.slider_sd);
  constant("kSliderCorrelation", o.slider_correlation);
  constant("kSliderBias", o.slider_bias);
  constant("kSliderMissShare", o.slider_miss_share);
  out +=
      "// Per view condition: loss rate, mean frames; flip rate, mean frames; spike rate, mean "
      "frames\n// (frames observed in it).\ninline constexpr ViewRates kView = {{{\n";
  for (int c = 0; c < kViewConditions; ++c) {
    const EpisodeRates& r = o.view.condition[c];
    out += "    {" + Number(r.loss_rate) + ", " + Number(r.loss_mean_frames) + ", " +
           Number(r.flip_rate) + ", " + Number(r.flip_mean_frames) + ", " + Number(r.spike_rate) +
           ", " + Number(r.spike_mean_frames) + "},  // " + ViewConditionName(c) + " (" +
           std::to_string(condition_frames[c]) + ")\n";
  }
  out += "}}};\n";
  return out;
}

namespace {

// What the pose errors of the tracking observations add up to: per type (0 rotation,
// 1 translation) the sum of squares over inlier frames, and per lag k = 1 .. kCoreLags over the
// pairs of inlier frames k apart the products and the mean squares of the pair; the episodes'
// runs; over twin frames the sums of the error angle and distance and their count, the lost
// frames inside flip episodes, over spike frames the squares per type.
using LagSums = std::array<std::array<double, 2>, kCoreLags>;
struct PoseErrorSums {
  std::array<double, 2> squares = {0, 0};
  LagSums lag_products{}, lag_squares{};
  Runs flip_runs, spike_runs, loss_runs;
  double flip_angle_sum = 0, flip_distance_sum = 0;
  std::int64_t twin_frames = 0, flip_lost_frames = 0;
  std::array<double, 2> spike_squares = {0, 0};
};

struct GrossThresholds {
  double rotation_rad = 0.0;
  double translation_m = 0.0;
};

// One take's frames into `sums`: each frame classified as lost, a flip (a gross error of more than
// a half turn), a spike (another gross error) or an inlier, by view condition.
void AddTracking(const TakeFrames& take, const ErrorModelOptions& prior,
                 const GrossThresholds& gross_threshold, PoseErrorSums* sums,
                 ErrorModelEstimate* estimate) {
  const std::size_t n = take.frames.size();
  std::vector<bool> lost(n), flip(n), spike(n), inlier(n), lost_or_flip(n);
  std::vector<int> condition(n);
  for (std::size_t t = 0; t < n; ++t) {
    const TrackingFrame& f = take.frames[t];
    condition[t] = ViewConditionOf(f.heading_deg, f.tilt_deg, prior.lying_tilt_deg);
    ++estimate->condition_frames[condition[t]];
    lost[t] = f.status == track::TrackStatus::kLost;
    if (lost[t]) continue;
    const std::array<double, 6>& error = f.error;
    const double angle = std::hypot(error[0], error[1], error[2]);
    const double distance = std::hypot(error[3], error[4], error[5]);
    const bool gross =
        angle > gross_threshold.rotation_rad || distance > gross_threshold.translation_m;
    flip[t] = gross && angle > kPi / 2;
    spike[t] = gross && !flip[t];
    inlier[t] = !gross;
    if (flip[t]) {
      sums->flip_angle_sum += angle;
      sums->flip_distance_sum += distance;
    }
    if (spike[t]) {
      for (int k = 0; k < 6; ++k) sums->spike_squares[k / 3] += error[k] * error[k];
    }
    if (!inlier[t]) continue;
    ++estimate->inlier_frames;
    for (int k = 0; k < 6; ++k) sums->squares[k / 3] += error[k] * error[k];
  }
  for (int lag = 1; lag <= kCoreLags; ++lag) {
    for (std::size_t t = 0; t + lag < n; ++t) {
      if (!inlier[t] || !inlier[t + lag]) continue;
      const std::array<double, 6>& a = take.frames[t].error;
      const std::array<double, 6>& b = take.frames[t + lag].error;
      for (int k = 0; k < 6; ++k) {
        sums->lag_products[lag - 1][k / 3] += a[k] * b[k];
        sums->lag_squares[lag - 1][k / 3] += 0.5 * (a[k] * a[k] + b[k] * b[k]);
      }
    }
  }
  estimate->frames += static_cast<std::int64_t>(n);
  // Flip episodes: the runs of twin and lost frames that hold a twin frame.
  for (std::size_t t = 0; t < n; ++t) lost_or_flip[t] = lost[t] || flip[t];
  std::vector<bool> in_flip(n, false), other_lost(n, false);
  for (std::size_t t = 0, end = 0; t < n; t = std::max(end, t + 1)) {
    for (end = t; end < n && lost_or_flip[end]; ++end) {}
    const bool twin = std::find(flip.begin() + t, flip.begin() + end, true) != flip.begin() + end;
    for (std::size_t u = t; u < end; ++u) in_flip[u] = twin;
  }
  for (std::size_t t = 0; t < n; ++t) {
    other_lost[t] = lost[t] && !in_flip[t];
    if (in_flip[t] && lost[t]) ++sums->flip_lost_frames;
    if (flip[t]) ++sums->twin_frames;
  }
  CountRuns(in_flip, std::vector<bool>(n, false), condition, &sums->flip_runs);
  CountRuns(other_lost, in_flip, condition, &sums->loss_runs);
  CountRuns(spike, lost_or_flip, condition, &sums->spike_runs);
}

// The core's time scales: the drift's share w and lag one ρ_s, the jitter's lag one ρ_f.
struct TimeScales {
  double slow_share = 0.0, slow_correlation = 0.0, correlation = 0.0;
};
using Autocorrelation = std::array<double, kCoreLags>;

// w ρ_s^k + (1 − w) ρ_f^k at lags 1 .. kCoreLags.
Autocorrelation ModelAutocorrelation(const TimeScales& m) {
  Autocorrelation out;
  double s = 1.0, f = 1.0;
  for (int k = 0; k < kCoreLags; ++k) {
    s *= m.slow_correlation;
    f *= m.correlation;
    out[k] = m.slow_share * s + (1.0 - m.slow_share) * f;
  }
  return out;
}

// The time scales whose autocorrelation is nearest to `acf` in least squares: ρ_s and ρ_f ≤ ρ_s
// on the grid i / 1000, i = 0 .. 999 (every pair tried), w in [0, 1] in closed form for each pair
// (the residual acf_k − ρ_f^k is linear in w with slope ρ_s^k − ρ_f^k). Ties keep the first pair.
TimeScales FitTimeScales(const Autocorrelation& acf) {
  constexpr int kGrid = 1000;
  static const std::vector<Autocorrelation> powers = [] {
    std::vector<Autocorrelation> p(kGrid);
    for (int i = 0; i < kGrid; ++i) p[i] = ModelAutocorrelation({0.0, 0.0, i / double{kGrid}});
    return p;
  }();
  TimeScales best;
  double best_error = std::numeric_limits<double>::infinity();
  for (int i = 0; i < kGrid; ++i) {
    for (int j = 0; j <= i; ++j) {
      double ab = 0, bb = 0, aa = 0;
      for (int k = 0; k < kCoreLags; ++k) {
        const double a = acf[k] - powers[j][k], b = powers[i][k] - powers[j][k];
        ab += a * b;
        bb += b * b;
        aa += a * a;
      }
      const double w = bb > 0 ? std::clamp(ab / bb, 0.0, 1.0) : 0.0;
      const double error = aa - 2 * w * ab + w * w * bb;
      if (error < best_error) {
        best_error = error;
        best = {w, i / double{kGrid}, j / double{kGrid}};
      }
    }
  }
  return best;
}

// The autocorrelation at each lag pooled over the two types, each scaled by its variance
// sd[type]²; false where a lag has no pairs.
bool PooledAutocorrelation(const LagSums& products, const LagSums& squares,
                           const std::array<double, 2>& sd, Autocorrelation* acf) {
  for (int k = 0; k < kCoreLags; ++k) {
    double numerator = 0, denominator = 0;
    for (int type = 0; type < 2; ++type) {
      if (sd[type] <= 0 || squares[k][type] <= 0) continue;
      numerator += products[k][type] / (sd[type] * sd[type]);
      denominator += squares[k][type] / (sd[type] * sd[type]);
    }
    if (!(denominator > 0)) return false;
    (*acf)[k] = numerator / denominator;
  }
  return true;
}

// The pose error's parameters from the sums: inlier sds per axis, the core's time scales from the
// autocorrelation pooled over the six components (each type scaled by its variance), the
// episodes' hazards per view condition, and the flips' and spikes' sizes.
void FitPoseErrors(const PoseErrorSums& sums, ErrorModelEstimate* estimate) {
  estimate->lost_frames = sums.loss_runs.Total(sums.loss_runs.frames);
  estimate->flip_frames = sums.flip_runs.Total(sums.flip_runs.frames);
  estimate->flip_lost_frames = sums.flip_lost_frames;
  estimate->spike_frames = sums.spike_runs.Total(sums.spike_runs.frames);
  estimate->loss_episodes = static_cast<int>(sums.loss_runs.Total(sums.loss_runs.starts));
  estimate->flip_episodes = static_cast<int>(sums.flip_runs.Total(sums.flip_runs.starts));
  estimate->spike_episodes = static_cast<int>(sums.spike_runs.Total(sums.spike_runs.starts));
  ErrorModelOptions& fit = estimate->options;
  if (estimate->inlier_frames > 0) {
    const double axes = 3.0 * static_cast<double>(estimate->inlier_frames);
    fit.rotation_sd = std::sqrt(sums.squares[0] / axes);
    fit.translation_sd = std::sqrt(sums.squares[1] / axes);
  }
  if (PooledAutocorrelation(sums.lag_products, sums.lag_squares,
                            {fit.rotation_sd, fit.translation_sd},
                            &estimate->core_autocorrelation)) {
    const TimeScales scales = FitTimeScales(estimate->core_autocorrelation);
    fit.slow_share = scales.slow_share;
    fit.slow_correlation = scales.slow_correlation;
    fit.correlation = scales.correlation;
  }
  FitHazards(sums.loss_runs, &EpisodeRates::loss_rate, &EpisodeRates::loss_mean_frames, &fit.view);
  FitHazards(sums.flip_runs, &EpisodeRates::flip_rate, &EpisodeRates::flip_mean_frames, &fit.view);
  FitHazards(sums.spike_runs, &EpisodeRates::spike_rate, &EpisodeRates::spike_mean_frames,
             &fit.view);
  if (sums.twin_frames > 0) {
    const double frames = static_cast<double>(sums.twin_frames);
    fit.flip_rotation = sums.flip_angle_sum / frames;
    fit.flip_translation = sums.flip_distance_sum / frames;
  }
  if (estimate->flip_frames > 0) {
    fit.flip_lost_share = static_cast<double>(sums.flip_lost_frames) /
                          static_cast<double>(estimate->flip_frames);
  }
  if (estimate->spike_frames > 0) {
    const double frames = static_cast<double>(estimate->spike_frames);
    fit.spike_rotation_sd = std::sqrt(sums.spike_squares[0] / (3 * frames));
    fit.spike_translation_sd = std::sqrt(sums.spike_squares[1] / (3 * frames));
  }
}

// The slider reading's error over the found frames: bias, sd, lag-one correlation (of the errors
// less the bias) and the share of frames where the block was not found.
void FitSlider(const std::vector<ReadingObservation>& readings, ErrorModelEstimate* estimate) {
  ErrorModelOptions& fit = estimate->options;
  double sum = 0, sum_squares = 0, slider_lag_product = 0, slider_lag_squares = 0;
  std::int64_t found_frames = 0;
  for (std::size_t i = 0; i < readings.size(); ++i) {
    const auto& obs = readings[i];
    const std::string name = "reading observation " + std::to_string(i);
    if (!obs.truth || !obs.read || !obs.found) throw InputError(name + ": missing data");
    const std::size_t n = obs.truth->size();
    if (obs.read->size() != n || obs.found->size() != n) {
      throw InputError(name + ": truth, read and found lengths differ (" + std::to_string(n) +
                       ", " + std::to_string(obs.read->size()) + ", " +
                       std::to_string(obs.found->size()) + ")");
    }
    estimate->slider_frames += static_cast<std::int64_t>(n);
    for (std::size_t t = 0; t < n; ++t) {
      if (!(*obs.found)[t]) {
        ++estimate->slider_missed;
        continue;
      }
      const double e = obs.read->values[t] - obs.truth->values[t];
      sum += e;
      sum_squares += e * e;
      ++found_frames;
    }
  }
  if (found_frames > 1) {
    const double count = static_cast<double>(found_frames);
    const double bias = sum / count;
    fit.slider_bias = bias;
    fit.slider_sd = std::sqrt(std::max(0.0, (sum_squares - count * bias * bias) / (count - 1)));
    estimate->slider_rmse = std::sqrt(sum_squares / count);
    for (const auto& obs : readings) {
      const std::size_t n = obs.truth->size();
      for (std::size_t t = 0; t + 1 < n; ++t) {
        if (!(*obs.found)[t] || !(*obs.found)[t + 1]) continue;
        const double a = obs.read->values[t] - obs.truth->values[t] - bias;
        const double b = obs.read->values[t + 1] - obs.truth->values[t + 1] - bias;
        slider_lag_product += a * b;
        slider_lag_squares += 0.5 * (a * a + b * b);
      }
    }
    if (slider_lag_squares > 0) {
      fit.slider_correlation = std::clamp(slider_lag_product / slider_lag_squares, 0.0, 0.999);
    }
  }
  if (estimate->slider_frames > 0) {
    fit.slider_miss_share = static_cast<double>(estimate->slider_missed) /
                            static_cast<double>(estimate->slider_frames);
  }
}

// ---- The correction by simulation (EstimateErrorModel's header) -----------------------------

// The parts of the model the correction fits, pooled over the view conditions, and the same
// quantities as the moment fit measures them.
struct PooledSpikes {
  double rotation_sd = 0.0, translation_sd = 0.0;
  double correlation = 0.0, slow_share = 0.0, slow_correlation = 0.0;  // the core's time scales
  double rate = 0.0, mean_frames = 1.0;  // spike episodes per free frame, mean length
  double spike_rotation_sd = 0.0, spike_translation_sd = 0.0;
  // As measured: the inliers' pooled autocorrelation at lags 1 .. kCoreLags.
  Autocorrelation acf{};

  TimeScales Scales() const { return {slow_share, slow_correlation, correlation}; }
  void SetScales(const TimeScales& m) {
    slow_share = m.slow_share;
    slow_correlation = m.slow_correlation;
    correlation = m.correlation;
  }
};

// The moments of `model`'s frames: `frames` frames of the six axes' cores with spike
// episodes drawn as SimulateTracking draws them (one view condition), split at the thresholds as
// AddTracking splits them and fitted as FitPoseErrors fits them. Fixed seeds: the same random
// numbers in every call, so the result is a deterministic function of the model.
PooledSpikes SimulatedMoments(const PooledSpikes& model, const GrossThresholds& gross,
                              int frames = 1 << 18) {
  constexpr std::uint64_t kSeed = 0x6d6f6d656e7473;  // "moments"
  people::Random core_random(people::DeriveSeed(kSeed, {kPoseStream}));
  people::Random slow_random(people::DeriveSeed(kSeed, {kSlowStream}));
  people::Random episode_random(people::DeriveSeed(kSeed, {kSpikeStream}));
  people::Random shape_random(people::DeriveSeed(kSeed, {kSpikeShapeStream}));
  std::array<Core, 6> axes = CoreAxes(model);
  std::array<double, 2> squares = {0, 0};
  LagSums lag_products{}, lag_squares{};
  std::array<double, 2> spike_squares = {0, 0};
  std::int64_t inliers = 0, starts = 0, at_risk = 0, spike_frames = 0, ends = 0;
  std::array<double, 6> spike{};
  // The last kCoreLags frames' errors and whether they were inliers (frame t in slot t % lags).
  std::array<std::array<double, 6>, kCoreLags> history{};
  std::array<bool, kCoreLags> history_inlier{};
  bool in_episode = false, previous_spike = false;
  for (int t = 0; t < frames; ++t) {
    // The episode chain first (DrawEpisodes), then the frame's error (SimulateTracking).
    bool spiking = in_episode;
    if (!in_episode && episode_random.Bernoulli(model.rate)) {
      spiking = in_episode = true;
      for (int k = 0; k < 3; ++k) spike[k] = shape_random.Normal(0, model.spike_rotation_sd);
      for (int k = 3; k < 6; ++k) spike[k] = shape_random.Normal(0, model.spike_translation_sd);
    }
    if (in_episode && episode_random.Bernoulli(1.0 / model.mean_frames)) in_episode = false;
    std::array<double, 6> x;
    for (int k = 0; k < 6; ++k) {
      x[k] = axes[k].Next(core_random, slow_random) + (spiking ? spike[k] : 0.0);
    }
    const double angle = std::hypot(x[0], x[1], x[2]);
    const bool gross_frame =
        angle > gross.rotation_rad || std::hypot(x[3], x[4], x[5]) > gross.translation_m;
    // A turn past 90° would count as a flip: neither a spike nor free (CountRuns' exclusion).
    const bool flip_like = gross_frame && angle > kPi / 2;
    const bool spike_frame = gross_frame && !flip_like;
    if (spike_frame) {
      ++spike_frames;
      if (!previous_spike) ++starts, ++at_risk;
      for (int k = 0; k < 6; ++k) spike_squares[k / 3] += x[k] * x[k];
    } else if (!flip_like) {
      ++at_risk;
    }
    if (previous_spike && !spike_frame) ++ends;
    if (!gross_frame) {
      ++inliers;
      for (int k = 0; k < 6; ++k) squares[k / 3] += x[k] * x[k];
      for (int lag = 1; lag <= std::min(t, kCoreLags); ++lag) {
        const int slot = (t - lag) % kCoreLags;
        if (!history_inlier[slot]) continue;
        const std::array<double, 6>& before = history[slot];
        for (int k = 0; k < 6; ++k) {
          lag_products[lag - 1][k / 3] += before[k] * x[k];
          lag_squares[lag - 1][k / 3] += 0.5 * (before[k] * before[k] + x[k] * x[k]);
        }
      }
    }
    history[t % kCoreLags] = x;
    history_inlier[t % kCoreLags] = !gross_frame;
    previous_spike = spike_frame;
  }
  PooledSpikes seen = model;
  if (inliers > 0) {
    seen.rotation_sd = std::sqrt(squares[0] / (3.0 * static_cast<double>(inliers)));
    seen.translation_sd = std::sqrt(squares[1] / (3.0 * static_cast<double>(inliers)));
  }
  PooledAutocorrelation(lag_products, lag_squares, {seen.rotation_sd, seen.translation_sd},
                        &seen.acf);
  seen.rate = at_risk > 0 ? static_cast<double>(starts) / static_cast<double>(at_risk) : 0.0;
  if (ends > 0) seen.mean_frames = static_cast<double>(spike_frames) / static_cast<double>(ends);
  if (spike_frames > 0) {
    seen.spike_rotation_sd = std::sqrt(spike_squares[0] / (3.0 * static_cast<double>(spike_frames)));
    seen.spike_translation_sd =
        std::sqrt(spike_squares[1] / (3.0 * static_cast<double>(spike_frames)));
  }
  return seen;
}

// The model whose simulated moments are `measured`: a fixed-point iteration from `start`, sds
// scaled by measured / simulated, the rate and length moved by measured − simulated (rate ≥ 0,
// length ≥ 1), the time scales refitted (FitTimeScales) to their own autocorrelation moved by
// measured − simulated at every lag, until nothing moves by more than 1e-3 of its measured value
// (the autocorrelation: 1e-3 at any lag; at most
// max_iterations: the simulated moments are step functions of the rate and length, so the last
// steps need not settle; the simulation's own sampling error is larger). What moves: `Fitted`.
enum class Fitted { kCore, kCoreAndSpikes, kEpisodes };
PooledSpikes FitToMoments(const PooledSpikes& measured, const PooledSpikes& start, Fitted fitted,
                          const GrossThresholds& gross, int frames, int max_iterations,
                          int* iterations) {
  PooledSpikes model = start;
  for (*iterations = 1;; ++*iterations) {
    const PooledSpikes seen = SimulatedMoments(model, gross, frames);
    double change = 0.0;
    const auto scale = [&](double* value, double want, double got) {
      if (!(want > 0 && got > 0)) return;
      const double next = *value * want / got;
      change = std::max(change, std::abs(next - *value) / want);
      *value = next;
    };
    const auto shift = [&](double* value, double want, double got, double low, double high,
                           double unit) {
      const double next = std::clamp(*value + want - got, low, high);
      change = std::max(change, std::abs(next - *value) / unit);
      *value = next;
    };
    if (fitted != Fitted::kEpisodes) {
      scale(&model.rotation_sd, measured.rotation_sd, seen.rotation_sd);
      scale(&model.translation_sd, measured.translation_sd, seen.translation_sd);
      // The time scales whose own autocorrelation is moved by measured − simulated at every lag.
      const Autocorrelation now = ModelAutocorrelation(model.Scales());
      Autocorrelation target;
      for (int k = 0; k < kCoreLags; ++k) target[k] = now[k] + measured.acf[k] - seen.acf[k];
      model.SetScales(FitTimeScales(target));
      const Autocorrelation next = ModelAutocorrelation(model.Scales());
      for (int k = 0; k < kCoreLags; ++k) change = std::max(change, std::abs(next[k] - now[k]));
    }
    if (fitted == Fitted::kCoreAndSpikes) {
      scale(&model.spike_rotation_sd, measured.spike_rotation_sd, seen.spike_rotation_sd);
      scale(&model.spike_translation_sd, measured.spike_translation_sd,
            seen.spike_translation_sd);
    }
    if (fitted != Fitted::kCore) {
      shift(&model.rate, measured.rate, seen.rate, 0.0, 1.0, std::max(measured.rate, 1e-3));
      shift(&model.mean_frames, measured.mean_frames, seen.mean_frames, 1.0, 1e6,
            measured.mean_frames);
    }
    if (change <= 1e-3 || *iterations == max_iterations) break;
  }
  return model;
}

// Applies the correction to the moment fit in `estimate` (its options hold the moments).
void CorrectBySimulation(const PoseErrorSums& sums, const GrossThresholds& gross,
                         ErrorModelEstimate* estimate) {
  ErrorModelOptions& fit = estimate->options;
  const Runs& runs = sums.spike_runs;
  const std::int64_t at_risk = runs.Total(runs.at_risk), ends = runs.Total(runs.ends);
  // Too few gross runs to fit the spikes' sizes from: the moments stay (a study of a few seconds'
  // takes).
  constexpr int kMinSpikeEpisodes = 100;
  if (estimate->inlier_frames == 0 || at_risk == 0) return;
  if (estimate->spike_episodes < kMinSpikeEpisodes) return;
  PooledSpikes measured;
  measured.rotation_sd = fit.rotation_sd;
  measured.translation_sd = fit.translation_sd;
  measured.SetScales({fit.slow_share, fit.slow_correlation, fit.correlation});
  measured.acf = estimate->core_autocorrelation;
  measured.rate = static_cast<double>(runs.Total(runs.starts)) / static_cast<double>(at_risk);
  measured.mean_frames = ends > 0 ? static_cast<double>(runs.Total(runs.frames)) /
                                        static_cast<double>(ends)
                                  : 1.0;
  measured.spike_rotation_sd = fit.spike_rotation_sd;
  measured.spike_translation_sd = fit.spike_translation_sd;
  // The core alone first: when the spikes' starts are within 2 Poisson standard errors of its
  // own excursions' there are no spikes to fit (their size and visibility would not be
  // identified, and a condition's sampling error would be read as spikes).
  PooledSpikes core_start = measured;
  core_start.rate = 0.0;
  int core_iterations = 0;
  const PooledSpikes core =
      FitToMoments(measured, core_start, Fitted::kCore, gross, 1 << 18, 25, &core_iterations);
  const double core_rate = SimulatedMoments(core, gross).rate;
  const double expected_starts = core_rate * static_cast<double>(at_risk);
  const bool spikes = static_cast<double>(runs.Total(runs.starts)) >
                      expected_starts + 2.0 * std::sqrt(expected_starts);
  PooledSpikes model = core;
  if (spikes) {
    model = FitToMoments(measured, measured, Fitted::kCoreAndSpikes, gross, 1 << 18, 25,
                         &estimate->simulation_iterations);
    PooledSpikes core_only = model;
    core_only.rate = 0.0;
    estimate->core_excursion_rate = SimulatedMoments(core_only, gross).rate;
    estimate->spike_visibility =
        std::max(0.0, measured.rate - estimate->core_excursion_rate) / model.rate;
    // The model must give back the measured sizes: where no model of this form does (its hidden
    // spikes alone would exceed the inliers' spread, and the core's sd is driven towards 0), the
    // moments stay.
    const PooledSpikes seen = SimulatedMoments(model, gross);
    const auto off = [](double got, double want) { return std::abs(got - want) > 0.05 * want; };
    if (off(seen.rotation_sd, measured.rotation_sd) ||
        off(seen.translation_sd, measured.translation_sd) ||
        off(seen.spike_rotation_sd, measured.spike_rotation_sd) ||
        off(seen.spike_translation_sd, measured.spike_translation_sd)) {
      estimate->core_excursion_rate = 0.0;
      estimate->spike_visibility = 1.0;
      return;
    }
  } else {
    estimate->simulation_iterations = core_iterations;
    estimate->core_excursion_rate = core_rate;
  }
  fit.rotation_sd = model.rotation_sd;
  fit.translation_sd = model.translation_sd;
  fit.correlation = model.correlation;
  fit.slow_share = model.slow_share;
  fit.slow_correlation = model.slow_correlation;
  if (spikes) {
    fit.spike_rotation_sd = model.spike_rotation_sd;
    fit.spike_translation_sd = model.spike_translation_sd;
  }
  // Per view condition with data: the rate and length whose simulated moments (with the pooled
  // core and sizes) are the condition's; the relation is not linear (an episode that starts on
  // the frame after another ends merges with it into one run, more often the higher the rate).
  tbb::parallel_for(0, kViewConditions, [&](int c) {
    EpisodeRates& r = fit.view.condition[c];
    if (runs.at_risk[c] == 0) return;
    if (!spikes || model.rate == 0.0) {
      r.spike_rate = 0.0;
      return;
    }
    PooledSpikes condition = model;
    condition.rate = r.spike_rate;
    condition.mean_frames = runs.ends[c] > 0 ? r.spike_mean_frames : measured.mean_frames;
    PooledSpikes start = model;
    start.rate = std::max(0.0, r.spike_rate - estimate->core_excursion_rate) /
                 std::max(estimate->spike_visibility, 1e-3);
    start.mean_frames =
        std::max(1.0, condition.mean_frames * model.mean_frames / measured.mean_frames);
    int iterations = 0;
    const PooledSpikes fitted =
        FitToMoments(condition, start, Fitted::kEpisodes, gross, 1 << 16, 15, &iterations);
    r.spike_rate = fitted.rate;
    // Without episodes the length is not identified (the iteration leaves it anywhere): the
    // measured one stays.
    if (runs.ends[c] > 0 && fitted.rate > 0) r.spike_mean_frames = fitted.mean_frames;
  });
  estimate->corrected = true;
}

// The pose errors' fit (moments, then the correction) from the takes' frames, and the slider's.
ErrorModelEstimate Estimate(const std::vector<const TakeFrames*>& takes,
                            const std::vector<ReadingObservation>& readings,
                            const ErrorModelOptions& prior, double gross_threshold_deg,
                            double gross_threshold_m) {
  ErrorModelEstimate estimate;
  estimate.options = prior;
  const GrossThresholds gross{gross_threshold_deg * kPi / 180.0, gross_threshold_m};
  PoseErrorSums sums;
  for (const TakeFrames* take : takes) AddTracking(*take, prior, gross, &sums, &estimate);
  FitPoseErrors(sums, &estimate);
  estimate.moments = estimate.options;
  CorrectBySimulation(sums, gross, &estimate);
  FitSlider(readings, &estimate);
  return estimate;
}

}  // namespace

ErrorModelEstimate EstimateErrorModel(const std::vector<TrackingObservation>& tracking,
                                      const std::vector<ReadingObservation>& readings,
                                      const ErrorModelOptions& prior, double gross_threshold_deg,
                                      double gross_threshold_m) {
  std::vector<TakeFrames> frames;
  std::vector<const TakeFrames*> takes;
  frames.reserve(tracking.size());
  for (std::size_t i = 0; i < tracking.size(); ++i) {
    frames.push_back(MeasureTakeFrames("", static_cast<int>(i), tracking[i], nullptr));
  }
  for (const TakeFrames& take : frames) takes.push_back(&take);
  return Estimate(takes, readings, prior, gross_threshold_deg, gross_threshold_m);
}

ErrorModelEstimate EstimateErrorModel(const std::vector<TakeFrames>& frames,
                                      const ErrorModelOptions& prior, double gross_threshold_deg,
                                      double gross_threshold_m) {
  std::vector<const TakeFrames*> takes;
  // The slider readings of the annotated takes, as ReadingObservations.
  std::vector<Annotation> truth, read;
  std::vector<std::vector<bool>> found;
  for (const TakeFrames& take : frames) {
    takes.push_back(&take);
    if (take.frames.empty() || !take.frames.front().has_slider) continue;
    Annotation& a = truth.emplace_back();
    Annotation& b = read.emplace_back();
    std::vector<bool>& c = found.emplace_back();
    for (const TrackingFrame& f : take.frames) {
      a.timestamps.push_back(f.time);
      a.values.push_back(f.slider_truth);
      b.timestamps.push_back(f.time);
      b.values.push_back(f.slider_read);
      c.push_back(f.slider_found);
    }
  }
  std::vector<ReadingObservation> readings;
  for (std::size_t i = 0; i < truth.size(); ++i) readings.push_back({&truth[i], &read[i], &found[i]});
  return Estimate(takes, readings, prior, gross_threshold_deg, gross_threshold_m);
}

}  // namespace mmh::pipeline
