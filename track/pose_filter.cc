#include "track/pose_filter.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "core/error.h"

namespace mmh::track {
namespace {

// alpha(f_c) = 1 / (1 + tau / dt), tau = 1 / (2 pi f_c).
double Alpha(double cutoff_hz, double dt) {
  const double tau = 1.0 / (2.0 * std::numbers::pi * cutoff_hz);
  return 1.0 / (1.0 + tau / dt);
}

}  // namespace

void PoseFilterOptions::Validate(const std::string& prefix) const {
  RequirePositive(min_cutoff_hz, prefix + ".min_cutoff_hz", "Hz");
  RequirePositive(derivative_cutoff_hz, prefix + ".derivative_cutoff_hz", "Hz");
  RequireNonNegative(translation_beta, prefix + ".translation_beta", "Hz s/m");
  RequireNonNegative(rotation_beta, prefix + ".rotation_beta", "Hz s");
}

PoseFilter::PoseFilter(const PoseFilterOptions& options) : options_(options) {
  options_.Validate("tracker.output_filter");
}

void PoseFilter::Reset() {
  last_time_.reset();
  velocity_.setZero();
  angular_.setZero();
}

Rigid3 PoseFilter::Filter(double timestamp, const Rigid3& camera_T_proxy) {
  if (!last_time_ || !(timestamp > *last_time_)) {
    Reset();
    last_time_ = timestamp;
    pose_ = camera_T_proxy;
    return pose_;
  }
  const double dt = timestamp - *last_time_;
  last_time_ = timestamp;
  const double alpha_d = Alpha(options_.derivative_cutoff_hz, dt);

  const Eigen::Vector3d velocity = (camera_T_proxy.translation - pose_.translation) / dt;
  velocity_ += alpha_d * (velocity - velocity_);
  const double translation_cutoff =
      options_.min_cutoff_hz + options_.translation_beta * velocity_.norm();
  pose_.translation +=
      Alpha(translation_cutoff, dt) * (camera_T_proxy.translation - pose_.translation);

  const Eigen::Vector3d angular =
      RotationVector(pose_.rotation.conjugate() * camera_T_proxy.rotation) / dt;
  angular_ += alpha_d * (angular - angular_);
  const double rotation_cutoff = options_.min_cutoff_hz + options_.rotation_beta * angular_.norm();
  // Eigen's slerp takes the shorter arc.
  pose_.rotation =
      pose_.rotation.slerp(Alpha(rotation_cutoff, dt), camera_T_proxy.rotation).normalized();
  return pose_;
}

}  // namespace mmh::track
