#include "track/motion_model.h"

#include <Eigen/Geometry>
#include <algorithm>

#include "core/error.h"

namespace mmh::track {

void MotionOptions::Validate(const std::string& prefix) const {
  if (!(memory >= 0 && memory < 1)) {
    ThrowBadValue(prefix + ".memory", FormatNumber(memory), "a number in [0, 1)");
  }
  if (!(stop_below >= 0 && stop_below <= 1)) {
    ThrowBadValue(prefix + ".stop_below", FormatNumber(stop_below), "a number in [0, 1]");
  }
  if (!(continue_above >= stop_below && continue_above <= 1)) {
    ThrowBadValue(prefix + ".continue_above", FormatNumber(continue_above),
                  "a number in [stop_below, 1] = [" + FormatNumber(stop_below) + ", 1]");
  }
}

MotionModel::MotionModel(const MotionOptions& options, const Eigen::Vector3d& centroid,
                         double radius)
    : options_(options),
      proxy_T_centroid_(Eigen::Quaterniond::Identity(), centroid),
      radius_(radius) {}

void MotionModel::Measure(const Rigid3& camera_T_proxy, bool continues) {
  if (continues && last_) {
    velocity_ = camera_T_proxy * last_->Inverse();
    // The step in the proxy's frame about its centroid: constant when the motion is (when each
    // pose is the last one times the same step, which is what Predict continues).
    const Rigid3 centroid_step =
        proxy_T_centroid_.Inverse() * last_->Inverse() * camera_T_proxy * proxy_T_centroid_;
    const Eigen::AngleAxisd turn(centroid_step.rotation);
    Eigen::Matrix<double, 6, 1> step;
    step << centroid_step.translation, turn.angle() * radius_ * turn.axis();
    if (last_step_) {
      numerator_ = options_.memory * numerator_ + step.dot(*last_step_);
      denominator_ = options_.memory * denominator_ + last_step_->squaredNorm();
    }
    last_step_ = step;
  } else {
    velocity_.reset();
    last_step_.reset();
  }
  last_ = camera_T_proxy;
}

Rigid3 MotionModel::Coast() {
  if (velocity_) velocity_ = Interpolate(Rigid3::Identity(), *velocity_, 0.5);
  last_ = Predict();
  // The next measured step spans a coasted frame: it does not pair with the one before.
  last_step_.reset();
  return *last_;
}

void MotionModel::Reset() {
  last_.reset();
  velocity_.reset();
  last_step_.reset();
  numerator_ = denominator_ = 0.0;
}

double MotionModel::factor() const { return denominator_ > 0 ? numerator_ / denominator_ : 1.0; }

double MotionModel::persistence() const {
  if (!options_.adaptive) return 1.0;
  const double a = factor();
  const double low = options_.stop_below, high = options_.continue_above;
  if (high <= low) return a >= high ? 1.0 : 0.0;
  return std::clamp((a - low) / (high - low), 0.0, 1.0);
}

std::optional<Rigid3> MotionModel::Predict() const {
  if (!last_ || !velocity_) return last_;
  const double a = persistence();
  // Exactly constant velocity at a = 1 (velocity_ * last_ = last_ * step).
  if (a >= 1.0) return *velocity_ * *last_;
  // The step in the proxy's frame about its centroid, scaled: the rotation by a about the
  // centroid, the centroid by a along its displacement.
  const Rigid3 step =
      proxy_T_centroid_.Inverse() * last_->Inverse() * *velocity_ * *last_ * proxy_T_centroid_;
  return *last_ * proxy_T_centroid_ * Interpolate(Rigid3::Identity(), step, a) *
         proxy_T_centroid_.Inverse();
}

}  // namespace mmh::track
