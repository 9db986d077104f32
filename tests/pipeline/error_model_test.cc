// The fast-fidelity error model: the statistics of its simulated errors match its options within
// sampling-theory tolerances (4 standard errors), the estimator recovers the options, and the
// draws are deterministic per seed.
#include "pipeline/error_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "core/error.h"

namespace mmh::pipeline {
namespace {

constexpr double kPi = 3.14159265358979323846;
// The camera of configs/soldier.json (table frame).
const Eigen::Vector3d kCamera(0.0, -0.9, 0.75);

// A slow circular walk with turning, #frames at 30 fps.
Trajectory Walk(int frames) {
  Trajectory walk;
  for (int t = 0; t < frames; ++t) {
    const double s = t / 30.0;
    walk.timestamps.push_back(s);
    const double heading = 0.3 * s;
    walk.poses.emplace_back(
        Eigen::Quaterniond(Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ())) *
            Eigen::Quaterniond(Eigen::AngleAxisd(0.2 * std::sin(s), Eigen::Vector3d::UnitX())),
        Eigen::Vector3d(0.1 * std::cos(heading), 0.1 * std::sin(heading), 0.05));
  }
  return walk;
}

// The error components in the proxy frame, computed directly (independent of the estimator).
std::array<double, 6> Error(const Rigid3& truth, const Rigid3& tracked) {
  Eigen::Quaterniond q = truth.rotation.conjugate() * tracked.rotation;
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  // Small angles: the rotation vector is 2·(x, y, z) of the quaternion to third order.
  const Eigen::AngleAxisd aa(q);
  const Eigen::Vector3d r = aa.angle() * aa.axis();
  const Eigen::Vector3d e = truth.rotation.conjugate() * (tracked.translation - truth.translation);
  return {r.x(), r.y(), r.z(), e.x(), e.y(), e.z()};
}

// Relative standard error of a sample SD from n values of a stationary AR(1) with lag-one
// correlation rho: Var(s²)/σ⁴ ≈ 2(1 + ρ²)/((1 − ρ²) n), and s has half that relative error.
double SdRelativeError(double n, double rho) {
  return 0.5 * std::sqrt(2 * (1 + rho * rho) / ((1 - rho * rho) * n));
}

TEST(ErrorModelTest, PoseErrorsHaveTheModelsSdAndCorrelation) {
  ErrorModelOptions options;
  options.translation_sd = 0.002;
  options.rotation_sd = 0.01;
  options.correlation = 0.8;
  options.slow_share = 0.0;               // one AR(1) (TheCoreHasTwoTimeScales: two)
  options.view = ViewRates::Uniform({});  // no episodes
  const int frames = 40000;
  const Trajectory truth = Walk(frames);
  const SimulatedTracking sim = SimulateTracking(truth, options, 7, kCamera);
  ASSERT_EQ(sim.tracked.size(), truth.size());
  double sq_r = 0, sq_t = 0, lag = 0, lag_sq = 0;
  std::array<double, 6> previous{};
  for (int t = 0; t < frames; ++t) {
    EXPECT_EQ(sim.status[t], track::TrackStatus::kTracked);
    const auto e = Error(truth.poses[t], sim.tracked.poses[t]);
    for (int k = 0; k < 3; ++k) sq_r += e[k] * e[k];
    for (int k = 3; k < 6; ++k) sq_t += e[k] * e[k];
    if (t > 0) {
      for (int k = 0; k < 6; ++k) {
        const double sd = k < 3 ? options.rotation_sd : options.translation_sd;
        lag += e[k] * previous[k] / (sd * sd);
        lag_sq += e[k] * e[k] / (sd * sd);
      }
    }
    previous = e;
  }
  const double n = 3.0 * frames;
  const double tolerance = 4 * SdRelativeError(n, options.correlation);
  EXPECT_NEAR(std::sqrt(sq_r / n), options.rotation_sd, tolerance * options.rotation_sd);
  EXPECT_NEAR(std::sqrt(sq_t / n), options.translation_sd, tolerance * options.translation_sd);
  // Standard error of an AR(1) lag-one estimate: sqrt((1 − ρ²)/n) over 6 components.
  EXPECT_NEAR(lag / lag_sq, options.correlation, 4 * std::sqrt((1 - 0.64) / (6.0 * frames)));
}

TEST(ErrorModelTest, TheCoreHasTwoTimeScales) {
  // x = drift + jitter: Corr(x_t, x_{t+k}) = w ρ_s^k + (1 − w) ρ_f^k, Var = σ².
  ErrorModelOptions options;
  options.translation_sd = 0.002;
  options.rotation_sd = 0.01;
  options.slow_share = 0.5;
  options.slow_correlation = 0.93;
  options.correlation = 0.15;
  options.view = ViewRates::Uniform({});
  const int frames = 100000;
  const Trajectory truth = Walk(frames);
  const SimulatedTracking sim = SimulateTracking(truth, options, 17, kCamera);
  std::vector<std::array<double, 6>> errors(frames);
  for (int t = 0; t < frames; ++t) errors[t] = Error(truth.poses[t], sim.tracked.poses[t]);
  double squares = 0;
  for (const auto& e : errors) {
    for (int k = 0; k < 6; ++k) {
      const double sd = k < 3 ? options.rotation_sd : options.translation_sd;
      squares += e[k] * e[k] / (sd * sd);
    }
  }
  // The drift's slow decay makes the sample variance noisier than an AR(1) at lag one would: its
  // effective sample is about n (1 − ρ_s) / (1 + ρ_s) per axis.
  const double effective = 6.0 * frames * (1 - 0.93) / (1 + 0.93);
  EXPECT_NEAR(squares / (6.0 * frames), 1.0, 4 * std::sqrt(2 / effective) * 0.5);
  for (int lag = 1; lag <= 8; ++lag) {
    double products = 0, lag_squares = 0;
    for (int t = 0; t + lag < frames; ++t) {
      for (int k = 0; k < 6; ++k) {
        const double sd = k < 3 ? options.rotation_sd : options.translation_sd;
        products += errors[t][k] * errors[t + lag][k] / (sd * sd);
        lag_squares += 0.5 * (errors[t][k] * errors[t][k] + errors[t + lag][k] * errors[t + lag][k]) /
                       (sd * sd);
      }
    }
    const double expected = 0.5 * std::pow(0.93, lag) + 0.5 * std::pow(0.15, lag);
    EXPECT_NEAR(products / lag_squares, expected, 4 / std::sqrt(effective)) << "lag " << lag;
  }
}

// Runs of frames where `flag` holds: (runs, frames in them, frames at risk = not flagged and not
// excluded, and the runs' first frames).
struct RunCount {
  int runs = 0, frames = 0, at_risk = 0;
};
RunCount CountRuns(const std::vector<bool>& flag, const std::vector<bool>& excluded) {
  RunCount c;
  for (std::size_t t = 0; t < flag.size(); ++t) {
    if (flag[t]) {
      ++c.frames;
      if (t == 0 || !flag[t - 1]) ++c.runs, ++c.at_risk;  // the start frame was free
    } else if (!excluded[t]) {
      ++c.at_risk;
    }
  }
  return c;
}

// Episode rates are near Poisson (relative standard error 1/sqrt(count)); geometric lengths have
// sd sqrt(1 - p)/p with p = 1/mean (episodes cut short by the next kind's frames bias the mean down
// a little: `slack`).
void ExpectEpisodes(const RunCount& c, double rate, double mean_frames, double slack,
                    const std::string& what) {
  ASSERT_GT(c.runs, 20) << what;
  EXPECT_NEAR(double(c.runs) / c.at_risk, rate, 4 * rate / std::sqrt(c.runs)) << what;
  const double sd = std::sqrt(1 - 1 / mean_frames) * mean_frames;
  EXPECT_NEAR(double(c.frames) / c.runs, mean_frames, 4 * sd / std::sqrt(c.runs) + slack) << what;
}

TEST(ErrorModelTest, EpisodesHaveTheModelsRatesLengthsAndSizes) {
  ErrorModelOptions options;
  options.rotation_sd = 0.0075;
  options.translation_sd = 0.0005;
  const EpisodeRates rates{.loss_rate = 0.01,
                           .loss_mean_frames = 4,
                           .flip_rate = 0.002,
                           .flip_mean_frames = 20,
                           .spike_rate = 0.01,
                           .spike_mean_frames = 2};
  options.view = ViewRates::Uniform(rates);
  options.flip_translation = 0.05;
  options.flip_lost_share = 0.3;
  options.spike_rotation_sd = 0.3;
  options.spike_translation_sd = 0.01;
  const int frames = 200000;
  const Trajectory truth = Walk(frames);
  const SimulatedTracking sim = SimulateTracking(truth, options, 11, kCamera);
  std::vector<bool> lost(frames), flip(frames), spike(frames), lost_or_flip(frames);
  double flip_angle = 0, flip_distance = 0;
  std::vector<std::array<double, 6>> spike_errors;  // one per spike episode (its first frame)
  for (int t = 0; t < frames; ++t) {
    lost[t] = sim.status[t] == track::TrackStatus::kLost;
    if (lost[t]) {
      EXPECT_TRUE(t == 0 ||
                  sim.tracked.poses[t].translation == sim.tracked.poses[t - 1].translation)
          << "a lost frame holds the last pose";
      lost_or_flip[t] = true;
      continue;
    }
    const auto e = Error(truth.poses[t], sim.tracked.poses[t]);
    const double angle = std::hypot(e[0], e[1], e[2]);
    const double distance = std::hypot(e[3], e[4], e[5]);
    flip[t] = angle > kPi / 2;
    // The core noise (0.0075 rad, 0.5 mm per axis) stays below 0.06 rad and 5 mm.
    spike[t] = !flip[t] && (angle > 0.06 || distance > 0.005);
    lost_or_flip[t] = flip[t];
    if (flip[t]) {
      flip_angle += angle;
      flip_distance += distance;
    }
    if (spike[t] && (t == 0 || !spike[t - 1])) spike_errors.push_back(e);
  }
  // A flip episode is a run of twin and lost frames holding a twin frame (drawn first, on every
  // frame); losses are the other lost runs (drawn on the frames outside flips).
  std::vector<bool> in_flip(frames, false), other_lost(frames, false);
  int twin_frames = 0, flip_lost_frames = 0;
  for (int t = 0; t < frames;) {
    int end = t;
    bool twin = false;
    while (end < frames && lost_or_flip[end]) twin = twin || flip[end], ++end;
    for (int u = t; u < end; ++u) {
      in_flip[u] = twin;
      other_lost[u] = !twin;
      if (twin && lost[u]) ++flip_lost_frames;
      if (flip[u]) ++twin_frames;
    }
    t = std::max(end, t + 1);
  }
  // A loss episode next to a flip merges with it (slack on the lengths).
  ExpectEpisodes(CountRuns(other_lost, in_flip), rates.loss_rate, rates.loss_mean_frames, 0.2,
                 "losses");
  const RunCount flips = CountRuns(in_flip, std::vector<bool>(frames, false));
  ExpectEpisodes(flips, rates.flip_rate, rates.flip_mean_frames, 1.0, "flips");
  // Each flip frame is lost with probability flip_lost_share (binomial).
  const double p = options.flip_lost_share;
  EXPECT_NEAR(double(flip_lost_frames) / flips.frames, p,
              4 * std::sqrt(p * (1 - p) / flips.frames) * 2);
  ExpectEpisodes(CountRuns(spike, lost_or_flip), rates.spike_rate, rates.spike_mean_frames, 0.1,
                 "spikes");
  // A flip turns the pose by pi (less the core noise) and moves it by flip_translation
  // horizontally (the core noise adds in quadrature).
  EXPECT_NEAR(flip_angle / twin_frames, options.flip_rotation, 0.03);
  EXPECT_NEAR(flip_distance / twin_frames, options.flip_translation, 0.002);
  // Spike sizes: per-axis RMS over episodes; chi-squared with 3 per episode, relative se of the RMS
  // 1/sqrt(6 episodes).
  double r2 = 0, e2 = 0;
  for (const auto& e : spike_errors) {
    for (int k = 0; k < 3; ++k) r2 += e[k] * e[k];
    for (int k = 3; k < 6; ++k) e2 += e[k] * e[k];
  }
  const double n = 3.0 * spike_errors.size();
  const double relative = 4 / std::sqrt(2 * n);
  // (The rotation vector of a large spike is the spike's own: its angle is below pi for these
  // sizes; wrapped ones are rare.)
  EXPECT_NEAR(std::sqrt(r2 / n), options.spike_rotation_sd, relative * options.spike_rotation_sd);
  EXPECT_NEAR(std::sqrt(e2 / n), options.spike_translation_sd,
              relative * options.spike_translation_sd + 0.0005);
}

TEST(ErrorModelTest, EstimatorRecoversTheOptions) {
  ErrorModelOptions options;
  options.translation_sd = 0.0007;
  options.rotation_sd = 0.009;
  options.correlation = 0.3;
  options.slow_share = 0.4;
  options.slow_correlation = 0.9;
  options.flip_lost_share = 0.2;
  const EpisodeRates rates{.loss_rate = 0.004,
                           .loss_mean_frames = 3,
                           .flip_rate = 0.0005,
                           .flip_mean_frames = 50,
                           .spike_rate = 0.005,
                           .spike_mean_frames = 1.5};
  options.view = ViewRates::Uniform(rates);
  options.flip_translation = 0.06;
  options.spike_rotation_sd = 0.4;
  options.spike_translation_sd = 0.02;
  options.slider_sd = 0.15;
  options.slider_correlation = 0.6;
  options.slider_bias = 0.05;
  options.slider_miss_share = 0.01;
  std::vector<Trajectory> truths;
  std::vector<SimulatedTracking> sims;
  std::vector<Annotation> slider_truths;
  std::vector<SimulatedReading> reads;
  for (int take = 0; take < 10; ++take) {
    truths.push_back(Walk(8000));
    sims.push_back(SimulateTracking(truths.back(), options, 100 + take, kCamera));
    Annotation a;
    for (int t = 0; t < 8000; ++t) {
      a.timestamps.push_back(t / 30.0);
      a.values.push_back(3 * std::sin(t / 200.0 + take));
    }
    slider_truths.push_back(a);
    reads.push_back(SimulateSliderReading(a, options, 200 + take));
  }
  std::vector<TrackingObservation> tracking;
  std::vector<ReadingObservation> readings;
  for (int take = 0; take < 10; ++take) {
    tracking.push_back({&truths[take], &sims[take].tracked, &sims[take].status, kCamera});
    readings.push_back({&slider_truths[take], &reads[take].read, &reads[take].found});
  }
  const ErrorModelEstimate estimate = EstimateErrorModel(tracking, readings, ErrorModelOptions{});
  const ErrorModelOptions& fit = estimate.options;
  const double n = 3.0 * estimate.inlier_frames;
  const double sd_tolerance = 4 * SdRelativeError(n * (1 - 0.9) / (1 + 0.9), 0.0);
  EXPECT_NEAR(fit.translation_sd, options.translation_sd, sd_tolerance * options.translation_sd);
  EXPECT_NEAR(fit.rotation_sd, options.rotation_sd, sd_tolerance * options.rotation_sd);
  // The time scales: the autocorrelation's sampling error at each lag is about
  // sqrt((1 + ρ_s)/(1 − ρ_s) / n) for the drift's share (n the inlier values): ±0.005 here; its
  // effect on the three parameters, found by refitting perturbed autocorrelations, is within
  // these bounds.
  EXPECT_NEAR(fit.slow_share, options.slow_share, 0.05);
  EXPECT_NEAR(fit.slow_correlation, options.slow_correlation, 0.02);
  EXPECT_NEAR(fit.correlation, options.correlation, 0.06);
  const double flip_p = options.flip_lost_share;
  EXPECT_NEAR(fit.flip_lost_share, flip_p,
              8 * std::sqrt(flip_p * (1 - flip_p) / estimate.flip_frames));
  // The hazards are fitted per view condition; with the same hazards in every condition their
  // frame-weighted means recover them (the walk sweeps every heading sector).
  const auto pooled = [&](double EpisodeRates::*member) {
    double sum = 0, weight = 0;
    for (int c = 0; c < kViewConditions; ++c) {
      sum += fit.view.condition[c].*member * estimate.condition_frames[c];
      weight += estimate.condition_frames[c];
    }
    return sum / weight;
  };
  EXPECT_NEAR(pooled(&EpisodeRates::loss_rate), rates.loss_rate,
              4 * rates.loss_rate / std::sqrt(estimate.loss_episodes));
  EXPECT_NEAR(pooled(&EpisodeRates::loss_mean_frames), rates.loss_mean_frames, 0.3);
  EXPECT_NEAR(pooled(&EpisodeRates::flip_rate), rates.flip_rate,
              4 * rates.flip_rate / std::sqrt(estimate.flip_episodes));
  // Flips run through their lost frames: about 40 episodes of 50 frames, too few per condition
  // for each condition's mean; over all of them frames / episodes (geometric: sd ≈ mean).
  EXPECT_NEAR(double(estimate.flip_frames) / estimate.flip_episodes, rates.flip_mean_frames,
              4 * rates.flip_mean_frames / std::sqrt(estimate.flip_episodes) + 1);
  EXPECT_NEAR(fit.flip_rotation, options.flip_rotation, 0.03);
  EXPECT_NEAR(fit.flip_translation, options.flip_translation, 0.003);
  // Spikes within the success criterion (5 deg, 1 cm) count as inliers: with these sizes few are.
  EXPECT_NEAR(pooled(&EpisodeRates::spike_rate), rates.spike_rate,
              4 * rates.spike_rate / std::sqrt(estimate.spike_episodes) + 0.0005);
  EXPECT_NEAR(fit.spike_rotation_sd, options.spike_rotation_sd, 0.1 * options.spike_rotation_sd);
  const double slider_n = double(estimate.slider_frames - estimate.slider_missed);
  const double slider_rel = SdRelativeError(slider_n, options.slider_correlation);
  EXPECT_NEAR(fit.slider_sd, options.slider_sd, 4 * slider_rel * options.slider_sd);
  // The mean of an AR(1) sample: se = σ sqrt((1 + ρ)/((1 − ρ) n)).
  EXPECT_NEAR(fit.slider_bias, options.slider_bias,
              4 * options.slider_sd * std::sqrt(1.6 / (0.4 * slider_n)));
  EXPECT_NEAR(fit.slider_correlation, options.slider_correlation, 0.02);
  const double p = options.slider_miss_share;
  EXPECT_NEAR(fit.slider_miss_share, p, 4 * std::sqrt(p * (1 - p) / estimate.slider_frames));
}

TEST(ErrorModelTest, ViewConditionIsTheHeadingSectorSeenFromTheCamera) {
  // A proxy at the origin, the camera on the −y side: facing the camera is heading −90° in the
  // table frame.
  const auto facing = [](double heading_deg, double tilt_deg = 0) {
    return Rigid3(
        Eigen::Quaterniond(Eigen::AngleAxisd(heading_deg * kPi / 180, Eigen::Vector3d::UnitZ()) *
                           Eigen::AngleAxisd(tilt_deg * kPi / 180, Eigen::Vector3d::UnitX())),
        Eigen::Vector3d::Zero());
  };
  EXPECT_EQ(ViewCondition(facing(-90), kCamera, 45), 0);     // facing the camera
  EXPECT_EQ(ViewCondition(facing(-75), kCamera, 45), 0);     // 15° counter-clockwise
  EXPECT_EQ(ViewCondition(facing(-105), kCamera, 45), 11);   // 15° clockwise
  EXPECT_EQ(ViewCondition(facing(0), kCamera, 45), 3);       // 90°: side-on
  EXPECT_EQ(ViewCondition(facing(90), kCamera, 45), 6);      // facing away
  EXPECT_EQ(ViewCondition(facing(170), kCamera, 45), 8);     // 260°
  EXPECT_EQ(ViewCondition(facing(90, 30), kCamera, 45), 6);  // leaning, still upright
  EXPECT_EQ(ViewCondition(facing(90, 60), kCamera, 45), kLying);
  EXPECT_EQ(ViewCondition(facing(0, 120), kCamera, 45), kLying);
  // The direction to the camera is taken from the proxy's position: a proxy at (0.9, −0.9)
  // facing −x faces the camera at (0, −0.9).
  Rigid3 beside = facing(180);
  beside.translation = Eigen::Vector3d(0.9, -0.9, 0);
  EXPECT_EQ(ViewCondition(beside, kCamera, 45), 0);
  EXPECT_STREQ(ViewConditionName(0), "heading_000");
  EXPECT_STREQ(ViewConditionName(6), "heading_180");
  EXPECT_STREQ(ViewConditionName(kLying), "lying");
  EXPECT_THROW(ViewConditionName(kViewConditions), InputError);
}

// A walk that turns through every heading and lies down for 5 s in every 20 s.
Trajectory WalkAndLie(int frames) {
  Trajectory walk = Walk(frames);
  for (int t = 0; t < frames; ++t) {
    if (t % 600 >= 450) {
      walk.poses[t].rotation = walk.poses[t].rotation * Eigen::Quaterniond(Eigen::AngleAxisd(
                                                            kPi / 2, Eigen::Vector3d::UnitY()));
    }
  }
  return walk;
}

TEST(ErrorModelTest, EpisodesFollowTheViewConditionAndTheEstimatorRecoversThem) {
  // Flips only facing away (heading_180) and lying, longer spikes while lying, losses everywhere.
  ErrorModelOptions options;
  options.view = ViewRates::Uniform({.loss_rate = 0.002,
                                     .loss_mean_frames = 2,
                                     .flip_rate = 0,
                                     .flip_mean_frames = 1,
                                     .spike_rate = 0.004,
                                     .spike_mean_frames = 2});
  options.view.condition[6].flip_rate = 0.02;
  options.view.condition[6].flip_mean_frames = 10;
  options.view.condition[kLying].flip_rate = 0.01;
  options.view.condition[kLying].flip_mean_frames = 30;
  options.view.condition[kLying].spike_rate = 0.03;
  // Spikes of 0.3 rad per axis pass 90° (and read as twins) once in 2e5 episodes; at 0.4 rad once
  // in 700.
  options.spike_rotation_sd = 0.3;
  options.spike_translation_sd = 0.02;
  // Flips without lost frames: a twin frame after a lost one would look like a new flip here.
  options.flip_lost_share = 0.0;
  // The core noise is the default (structured-light frames: 1.5 deg, 1.56 mm per axis), which by
  // itself goes past 5 deg on about 1 % of frames: the estimator must not count that as spikes.
  const int frames = 30000;
  std::vector<Trajectory> truths;
  std::vector<SimulatedTracking> sims;
  std::vector<TrackingObservation> tracking;
  for (int take = 0; take < 4; ++take) truths.push_back(WalkAndLie(frames));
  for (int take = 0; take < 4; ++take) {
    sims.push_back(SimulateTracking(truths[take], options, 300 + take, kCamera));
  }
  for (int take = 0; take < 4; ++take) {
    tracking.push_back({&truths[take], &sims[take].tracked, &sims[take].status, kCamera});
    // No flip starts where the flip rate is 0 (an episode may run on into the next condition).
    for (int t = 0; t < frames; ++t) {
      const auto e = Error(truths[take].poses[t], sims[take].tracked.poses[t]);
      const bool flip = std::hypot(e[0], e[1], e[2]) > kPi / 2;
      const auto prev = t > 0 ? Error(truths[take].poses[t - 1], sims[take].tracked.poses[t - 1])
                              : std::array<double, 6>{};
      const bool flip_before = t > 0 && std::hypot(prev[0], prev[1], prev[2]) > kPi / 2;
      if (flip && !flip_before && sims[take].status[t] != track::TrackStatus::kLost) {
        const int c = ViewCondition(truths[take].poses[t], kCamera, options.lying_tilt_deg);
        EXPECT_TRUE(c == 6 || c == kLying) << "flip starting in " << ViewConditionName(c);
      }
    }
  }
  const ErrorModelEstimate estimate = EstimateErrorModel(tracking, {}, options);
  std::int64_t total = 0;
  for (const auto n : estimate.condition_frames) total += n;
  EXPECT_EQ(total, 4 * frames);
  ASSERT_GT(estimate.condition_frames[kLying], 20000);
  // Each condition's hazards within 4 standard errors (Poisson counts over its frames).
  for (int c = 0; c < kViewConditions; ++c) {
    const EpisodeRates& truth = options.view.condition[c];
    const EpisodeRates& fit = estimate.options.view.condition[c];
    const double n = double(estimate.condition_frames[c]);
    ASSERT_GT(n, 3000) << ViewConditionName(c);
    // A loss episode that ends where a flip starts joins it (a flip episode is a run of twin and
    // lost frames), and the flip then starts in the loss's condition: about flips x the lost
    // frames' share of such starts, spread over the conditions.
    const double joined = estimate.flip_episodes * double(estimate.lost_frames) /
                          double(estimate.frames) / (4.0 * frames);
    EXPECT_NEAR(fit.flip_rate, truth.flip_rate,
                4 * std::sqrt((truth.flip_rate + joined) / (0.7 * n)))
        << ViewConditionName(c);
    // The spikes' count includes the core's own excursions, which are subtracted in expectation
    // but whose sampling error stays.
    EXPECT_NEAR(fit.spike_rate, truth.spike_rate,
                4 * std::sqrt((truth.spike_rate + estimate.core_excursion_rate) / (0.7 * n)))
        << ViewConditionName(c);
    EXPECT_NEAR(fit.loss_rate, truth.loss_rate, 4 * std::sqrt(truth.loss_rate / (0.7 * n)))
        << ViewConditionName(c);
  }
  // Lengths where there are many episodes: geometric, sd ≈ mean.
  const auto& lying = estimate.options.view.condition[kLying];
  EXPECT_NEAR(lying.flip_mean_frames, 30, 4 * 30 / std::sqrt(0.01 * 0.5 * 20000));
  EXPECT_NEAR(lying.spike_mean_frames, 2, 0.4);
}

// `takes` walks of `frames` frames (`walk`) tracked by the model with seeds first_seed + take, and
// their observations (pointing into the vectors, which must not be resized afterwards).
struct SimulatedTakes {
  std::vector<Trajectory> truths;
  std::vector<SimulatedTracking> sims;
  std::vector<TrackingObservation> tracking;
};
SimulatedTakes SimulateTakes(const ErrorModelOptions& options, Trajectory (*walk)(int), int takes,
                             int frames, std::uint64_t first_seed) {
  SimulatedTakes out;
  for (int take = 0; take < takes; ++take) out.truths.push_back(walk(frames));
  for (int take = 0; take < takes; ++take) {
    out.sims.push_back(SimulateTracking(out.truths[take], options, first_seed + take, kCamera));
  }
  for (int take = 0; take < takes; ++take) {
    out.tracking.push_back(
        {&out.truths[take], &out.sims[take].tracked, &out.sims[take].status, kCamera});
  }
  return out;
}

// The core process alone, with an sd that crosses the gross thresholds on a few per cent of frames
// and no spikes: by moments its excursions are spikes and its σ the RMS of the frames within the
// thresholds (computed here from the definitions); corrected by simulation, the spike rate is 0
// within sampling error and σ and ρ are the process's.
TEST(ErrorModelTest, TheCoresOwnExcursionsAreNotSpikes) {
  ErrorModelOptions options;
  options.view = ViewRates::Uniform({});  // no losses, flips or spikes
  options.rotation_sd = 0.035;            // 2 deg per axis: about 10 % of frames beyond 5 deg
  options.translation_sd = 0.002;
  options.correlation = 0.5;
  const int frames = 40000;
  const SimulatedTakes takes = SimulateTakes(options, Walk, 3, frames, 500);
  const auto& [truths, sims, tracking] = takes;
  // The truncated moments, computed here from the definitions.
  double squares = 0, inliers = 0;
  std::int64_t beyond = 0;
  for (int take = 0; take < 3; ++take) {
    for (int t = 0; t < frames; ++t) {
      const auto e = Error(truths[take].poses[t], sims[take].tracked.poses[t]);
      if (std::hypot(e[0], e[1], e[2]) > 5 * kPi / 180 || std::hypot(e[3], e[4], e[5]) > 0.01) {
        ++beyond;
        continue;
      }
      squares += e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
      inliers += 3;
    }
  }
  const double truncated_rms = std::sqrt(squares / inliers);
  const ErrorModelEstimate estimate = EstimateErrorModel(tracking, {}, options);
  EXPECT_EQ(estimate.spike_frames, beyond);
  ASSERT_GT(estimate.spike_episodes, 2000);  // what the moments count as spikes
  EXPECT_NEAR(estimate.moments.rotation_sd, truncated_rms, 1e-12 * truncated_rms);
  const double n = 3.0 * frames;
  for (int c = 0; c < kViewConditions; ++c) {
    const EpisodeRates& fit = estimate.options.view.condition[c];
    const double m = double(estimate.condition_frames[c]);
    if (m == 0) continue;
    // The starts' Poisson sd over this condition's frames, as a rate.
    EXPECT_LT(fit.spike_rate, 4 * std::sqrt(0.03 / m) + 0.002) << ViewConditionName(c);
  }
  // The truncated RMS understates σ (by 11 %); the fit undoes it.
  EXPECT_LT(truncated_rms, 0.95 * options.rotation_sd);
  const double sd_tolerance = 4 * SdRelativeError(n * (1 - 0.9) / (1 + 0.9), 0.0);
  EXPECT_NEAR(estimate.options.rotation_sd, options.rotation_sd,
              sd_tolerance * options.rotation_sd);
  EXPECT_NEAR(estimate.options.translation_sd, options.translation_sd,
              sd_tolerance * options.translation_sd);
  EXPECT_NEAR(estimate.options.correlation, options.correlation, 0.02);
}

// The committed defaults are a fixed point of simulate-then-estimate: fast-mode takes drawn from
// them give back their core noise, their spikes' sizes and their spike hazards pooled over the
// frames. (By moments alone, 2026-11-29: 5 % fewer spike starts, the translation sd 6 % and the
// spikes' rotation sd 10 % too large.)
TEST(ErrorModelTest, TheDefaultsAreRecoveredFromTheirOwnSimulation) {
  const ErrorModelOptions options;
  const SimulatedTakes takes = SimulateTakes(options, Walk, 4, 30000, 700);
  const ErrorModelEstimate estimate = EstimateErrorModel(takes.tracking, {}, options);
  const ErrorModelOptions& fit = estimate.options;
  // 1.5 %: the sampling error of these frames (4 se: 0.7 %) and of the estimator's own simulation
  // (0.45 %), and the pooled fit's bias where the conditions' spike rates differ (measured up to
  // 1 % on the translation). By moments alone the translation sd is 6-16 % too large.
  EXPECT_NEAR(fit.rotation_sd, options.rotation_sd, 0.015 * options.rotation_sd);
  EXPECT_NEAR(fit.translation_sd, options.translation_sd, 0.015 * options.translation_sd);
  // The core's time scales: what the data identify is the autocorrelation, here at lag 1 (over
  // 12 seeds of these takes, 2026-11-30, within 0.007 of the defaults'). The fast part's ρ_f
  // alone trades off against the slow part (w, ρ_s): over the same seeds it came back
  // 0.132 ± 0.005 (sd) against the defaults' 0.147 of 2026-11-30, with w and ρ_s a little larger
  // to compensate. At the defaults of 2026-12-02 (seeds 700-711, the lag-1 autocorrelation
  // within 0.002) ρ_f comes back 0.068 ± 0.005 against 0.107, w 0.503 against 0.485 and ρ_s
  // 0.965 against 0.958, so it is held to that bias and 4 sd. (Until 2026-11-30 ρ_f was held to
  // 0.02: seed 700 passed at the previous defaults, 0.144, and failed at these, 0.124.)
  auto lag_one = [](const ErrorModelOptions& m) {
    return m.slow_share * m.slow_correlation + (1 - m.slow_share) * m.correlation;
  };
  EXPECT_NEAR(lag_one(fit), lag_one(options), 0.02);
  EXPECT_NEAR(fit.correlation, options.correlation - 0.039, 4 * 0.005);
  // Pooled over the frames: Σ_c rate_c · at-risk frames is the expected number of starts.
  double expected = 0, fitted = 0;
  for (int c = 0; c < kViewConditions; ++c) {
    const double m = double(estimate.condition_frames[c]);
    expected += options.view.condition[c].spike_rate * m;
    fitted += fit.view.condition[c].spike_rate * m;
  }
  EXPECT_TRUE(estimate.corrected);
  EXPECT_NEAR(fitted, expected, 4 * std::sqrt(expected)) << "spike starts";
  // The spikes' sizes: the per-axis RMS of about 8 000 episodes' draws. Over seeds 700-711 at the
  // defaults of 2026-12-02 the fit's spread is twice the draws' standard error (sd 0.9 % for the
  // rotation, 1.1 % for the translation: the correction by simulation samples too) and the
  // translation's mean 1.0 % high (the pooled fit's bias, above): held to 1 % and 4 of the
  // measured sd. (At 4 draws' standard errors, 1.7 %, seed 700 failed the translation by 2.4 %.)
  const double size_tolerance = 0.01 + 4 * 0.011;
  EXPECT_NEAR(fit.spike_rotation_sd, options.spike_rotation_sd,
              size_tolerance * options.spike_rotation_sd);
  EXPECT_NEAR(fit.spike_translation_sd, options.spike_translation_sd,
              size_tolerance * options.spike_translation_sd);
}

// With fewer than 100 spike episodes (a study of a few seconds' takes) there is nothing to fit the
// spikes' sizes from: the moments are the fit.
TEST(ErrorModelTest, AShortSampleKeepsItsMoments) {
  const ErrorModelOptions options;
  const Trajectory truth = Walk(600);
  const SimulatedTracking sim = SimulateTracking(truth, options, 900, kCamera);
  const ErrorModelEstimate estimate =
      EstimateErrorModel({{&truth, &sim.tracked, &sim.status, kCamera}}, {}, options);
  ASSERT_GT(estimate.inlier_frames, 0);
  ASSERT_LT(estimate.spike_episodes, 100);
  EXPECT_FALSE(estimate.corrected);
  EXPECT_EQ(estimate.options.rotation_sd, estimate.moments.rotation_sd);
  EXPECT_EQ(estimate.options.translation_sd, estimate.moments.translation_sd);
  EXPECT_EQ(estimate.options.spike_rotation_sd, estimate.moments.spike_rotation_sd);
  for (int c = 0; c < kViewConditions; ++c) {
    EXPECT_EQ(estimate.options.view.condition[c].spike_rate,
              estimate.moments.view.condition[c].spike_rate);
  }
}

TEST(ErrorModelTest, TheCommittedDefaultsAreTheGeneratorsOutput) {
  // pipeline/error_model.inc is what DefaultsSource writes for the defaults it defines (after its
  // header comment, which says where they were measured): regenerating it from a study's fit is a
  // copy, and every default is read back exactly.
  ErrorModelEstimate estimate;
  const std::string generated = estimate.DefaultsSource("test");
  std::ifstream file(std::string(MMH_SOURCE_DIR) + "/pipeline/error_model.inc");
  ASSERT_TRUE(file.good());
  const std::string committed((std::istreambuf_iterator<char>(file)),
                              std::istreambuf_iterator<char>());
  const auto body = [](const std::string& text) {
    const auto start = text.find("inline constexpr");
    std::string out = text.substr(start);
    // The per-condition frame counts are comments.
    std::string stripped;
    std::istringstream lines(out);
    for (std::string line; std::getline(lines, line);) {
      const auto comment = line.find("  // ");
      stripped += (comment == std::string::npos ? line : line.substr(0, comment)) + "\n";
    }
    return stripped;
  };
  EXPECT_EQ(body(generated), body(committed));
  // Another estimate writes other numbers, and a study's fit compiles as the defaults.
  estimate.options.view.condition[6].flip_rate = 0.125;
  EXPECT_NE(body(estimate.DefaultsSource("test")), body(committed));
  EXPECT_NE(estimate.DefaultsSource("study X").find("0.125, "), std::string::npos);
}

TEST(ErrorModelTest, SliderReadingStaysInRangeAndHoldsMissedFrames) {
  ErrorModelOptions options;
  options.slider_sd = 0.5;
  options.slider_miss_share = 0.2;
  Annotation truth;
  for (int t = 0; t < 3000; ++t) {
    truth.timestamps.push_back(t / 30.0);
    truth.values.push_back(t % 600 < 300 ? 5.0 : -4.9);
  }
  const SimulatedReading read = SimulateSliderReading(truth, options, 3);
  ASSERT_EQ(read.read.size(), truth.size());
  int first_found = -1;
  for (int t = 0; t < 3000; ++t) {
    EXPECT_GE(read.read.values[t], kMinAnnotation);
    EXPECT_LE(read.read.values[t], kMaxAnnotation);
    if (read.found[t] && first_found < 0) first_found = t;
    if (!read.found[t] && t > 0) {
      EXPECT_EQ(read.read.values[t], read.read.values[t - 1]);
    }
  }
  ASSERT_GE(first_found, 0);
  for (int t = 0; t < first_found; ++t)
    EXPECT_EQ(read.read.values[t], read.read.values[first_found]);
  EXPECT_EQ(read.read.timestamps, truth.timestamps);
}

TEST(ErrorModelTest, DeterministicPerSeed) {
  ErrorModelOptions options;
  options.view.condition[0].loss_rate = 0.01;
  const Trajectory truth = Walk(2000);
  const auto a = SimulateTracking(truth, options, 5, kCamera);
  const auto b = SimulateTracking(truth, options, 5, kCamera);
  const auto c = SimulateTracking(truth, options, 6, kCamera);
  bool differs = false;
  for (std::size_t t = 0; t < truth.size(); ++t) {
    EXPECT_EQ(a.tracked.poses[t].translation, b.tracked.poses[t].translation);
    EXPECT_EQ(a.tracked.poses[t].rotation.coeffs(), b.tracked.poses[t].rotation.coeffs());
    EXPECT_EQ(a.status[t], b.status[t]);
    differs |= a.tracked.poses[t].translation != c.tracked.poses[t].translation;
  }
  EXPECT_TRUE(differs);
  Annotation slider;
  for (int t = 0; t < 500; ++t) {
    slider.timestamps.push_back(t / 30.0);
    slider.values.push_back(0.01 * t - 2);
  }
  EXPECT_EQ(SimulateSliderReading(slider, options, 9).read.values,
            SimulateSliderReading(slider, options, 9).read.values);
  EXPECT_NE(SimulateSliderReading(slider, options, 9).read.values,
            SimulateSliderReading(slider, options, 10).read.values);
}

TEST(ErrorModelTest, BadOptionsNameTheField) {
  ErrorModelOptions options;
  options.correlation = 1.0;
  try {
    options.Validate("error_model");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("error_model.correlation"), std::string::npos) << e.what();
  }
  options = {};
  options.view.condition[kLying].loss_mean_frames = 0.5;
  try {
    options.Validate("error_model");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("error_model.view.lying.loss_mean_frames"),
              std::string::npos)
        << e.what();
  }
  options = {};
  options.view.condition[6].flip_rate = 1.5;
  EXPECT_THROW(options.Validate("error_model"), InputError);
  options = {};
  options.lying_tilt_deg = 0;
  EXPECT_THROW(options.Validate("error_model"), InputError);
  options = {};
  options.translation_sd = std::nan("");
  EXPECT_THROW(SimulateTracking(Walk(10), options, 1, kCamera), InputError);
  options = {};
  options.slider_miss_share = 1.0;
  EXPECT_THROW(options.Validate("error_model"), InputError);
}

TEST(ErrorModelTest, EstimatorRejectsMismatchedLengths) {
  const Trajectory truth = Walk(10);
  const Trajectory shorter = Walk(9);
  const std::vector<track::TrackStatus> status(10, track::TrackStatus::kTracked);
  EXPECT_THROW(EstimateErrorModel({{&truth, &shorter, &status}}, {}), InputError);
}

}  // namespace
}  // namespace mmh::pipeline
