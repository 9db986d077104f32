#include "people/viewer.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "people/random.h"

namespace mmh::people {

void ViewerOptions::Validate(const std::string& prefix) const {
  RequireNonNegative(artefact_weight, prefix + ".artefact_weight");
  RequirePositive(velocity_threshold, prefix + ".velocity_threshold", "m/s");
  RequirePositive(angular_threshold, prefix + ".angular_threshold", "rad/s");
  RequireNonNegative(contrast, prefix + ".contrast");
  RequirePositive(context, prefix + ".context", "s");
  RequirePositive(artefact_cap, prefix + ".artefact_cap");
  if (smoothing < 1 || smoothing > 61 || smoothing % 2 == 0) {
    ThrowBadValue(prefix + ".smoothing", std::to_string(smoothing),
                  "an odd frame count in [1, 61]");
  }
  RequireNonNegative(quality_weight_sd, prefix + ".quality_weight_sd");
  RequireNonNegative(artefact_sensitivity_sd, prefix + ".artefact_sensitivity_sd");
  RequireNonNegative(judgement_noise, prefix + ".judgement_noise");
}

std::vector<double> ArtefactTrace(const Trajectory& animation, const ViewerOptions& options) {
  const auto& poses = animation.poses;
  const int n = static_cast<int>(poses.size());
  std::vector<double> artefact(n, 0.0);
  if (n < 4) return artefact;
  const double fps = 1.0 / MedianFramePeriod(animation.timestamps);
  // Smoothed positions and rotation vectors relative to the first frame (unwrapped per step).
  const int half = options.smoothing / 2;
  std::vector<Eigen::Vector3d> position(n), smooth_position(n);
  std::vector<Eigen::Vector3d> angle(n), smooth_angle(n);
  Eigen::Vector3d accumulated = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    position[i] = poses[i].translation;
    if (i > 0) {
      // Integrate the frame-to-frame rotation in the world frame: a continuous angle signal.
      accumulated += RotationVector(poses[i].rotation * poses[i - 1].rotation.conjugate());
    }
    angle[i] = accumulated;
  }
  for (int i = 0; i < n; ++i) {
    const int a = std::max(0, i - half), b = std::min(n - 1, i + half);
    Eigen::Vector3d p = Eigen::Vector3d::Zero(), r = Eigen::Vector3d::Zero();
    for (int k = a; k <= b; ++k) p += position[k], r += angle[k];
    smooth_position[i] = p / (b - a + 1);
    smooth_angle[i] = r / (b - a + 1);
  }
  // One-frame changes of the smoothed velocities.
  std::vector<double> dv(n, 0.0), dw(n, 0.0);
  for (int i = 1; i + 1 < n; ++i) {
    const Eigen::Vector3d v0 = (smooth_position[i] - smooth_position[i - 1]) * fps;
    const Eigen::Vector3d v1 = (smooth_position[i + 1] - smooth_position[i]) * fps;
    const Eigen::Vector3d w0 = (smooth_angle[i] - smooth_angle[i - 1]) * fps;
    const Eigen::Vector3d w1 = (smooth_angle[i + 1] - smooth_angle[i]) * fps;
    dv[i] = (v1 - v0).norm();
    dw[i] = (w1 - w0).norm();
  }
  // Prefix sums of the squares for the local rhythm ρ.
  std::vector<double> sv(n + 1, 0.0), sw(n + 1, 0.0);
  for (int i = 0; i < n; ++i) sv[i + 1] = sv[i] + dv[i] * dv[i], sw[i + 1] = sw[i] + dw[i] * dw[i];
  const int context = std::max(1, static_cast<int>(std::lround(options.context * fps)));
  const int exclude = options.smoothing;
  for (int i = 1; i + 1 < n; ++i) {
    const int a = std::max(0, i - context), b = std::min(n - 1, i + context);
    const int ea = std::max(a, i - exclude), eb = std::min(b, i + exclude);
    const int count = (b - a + 1) - (eb - ea + 1);
    double rho_v = 0, rho_w = 0;
    if (count > 0) {
      rho_v = std::sqrt((sv[b + 1] - sv[a] - (sv[eb + 1] - sv[ea])) / count);
      rho_w = std::sqrt((sw[b + 1] - sw[a] - (sw[eb + 1] - sw[ea])) / count);
    }
    const double translation =
        std::clamp(dv[i] / (options.contrast * rho_v + options.velocity_threshold) - 1, 0.0,
                   options.artefact_cap);
    const double rotation =
        std::clamp(dw[i] / (options.contrast * rho_w + options.angular_threshold) - 1, 0.0,
                   options.artefact_cap);
    artefact[i] = translation + rotation;
  }
  return artefact;
}

Appeal Appraise(const Trajectory& animation, std::span<const double> quality,
                const ViewerOptions& options) {
  options.Validate("viewer");
  const int n = static_cast<int>(animation.poses.size());
  if (static_cast<int>(quality.size()) != n) {
    ThrowBadValue("appraised animation", std::to_string(quality.size()) + " quality values",
                  "one per frame (" + std::to_string(n) + ")");
  }
  Appeal appeal;
  if (n == 0) return appeal;
  for (const double q : quality) appeal.mean_quality += q;
  appeal.mean_quality /= n;
  for (const double e : ArtefactTrace(animation, options)) {
    appeal.artefacts += e;
    appeal.artefact_frames += e > 0;
  }
  const double minutes = n > 1 ? n * MedianFramePeriod(animation.timestamps) / 60.0 : 1.0 / 60.0;
  appeal.artefacts_per_minute = appeal.artefacts / minutes;
  appeal.appeal = appeal.mean_quality - options.artefact_weight * appeal.artefacts_per_minute;
  return appeal;
}

Viewer DrawViewer(const ViewerOptions& options, std::uint64_t seed, int index) {
  Random random(DeriveSeed(seed, {0x7669ull, static_cast<std::uint64_t>(index)}));
  Viewer viewer;
  viewer.quality_weight = std::max(0.0, random.Normal(1.0, options.quality_weight_sd));
  viewer.artefact_sensitivity = std::exp(random.Normal(0.0, options.artefact_sensitivity_sd));
  return viewer;
}

double Utility(const Appeal& appeal, const Viewer& viewer, const ViewerOptions& options,
               std::uint64_t seed, std::uint64_t viewing) {
  Random random(DeriveSeed(seed, {0x7574ull, viewing}));
  return viewer.quality_weight * appeal.mean_quality -
         viewer.artefact_sensitivity * options.artefact_weight * appeal.artefacts_per_minute +
         random.Normal(0.0, options.judgement_noise);
}

std::vector<double> CompositeQuality(std::span<const std::vector<double>> take_quality,
                                     std::span<const int> take_of_frame,
                                     std::span<const int> source_frame) {
  if (take_of_frame.size() != source_frame.size()) {
    ThrowBadValue("composite", std::to_string(source_frame.size()) + " source frames",
                  "one per composite frame (" + std::to_string(take_of_frame.size()) + ")");
  }
  std::vector<double> quality(take_of_frame.size());
  for (std::size_t t = 0; t < quality.size(); ++t) {
    const int take = take_of_frame[t];
    if (take < 0 || take >= static_cast<int>(take_quality.size()) || source_frame[t] < 0 ||
        source_frame[t] >= static_cast<int>(take_quality[take].size())) {
      ThrowBadValue("composite frame " + std::to_string(t),
                    "take " + std::to_string(take) + " frame " + std::to_string(source_frame[t]),
                    "a frame of one of the " + std::to_string(take_quality.size()) + " takes");
    }
    quality[t] = take_quality[take][source_frame[t]];
  }
  return quality;
}

}  // namespace mmh::people
