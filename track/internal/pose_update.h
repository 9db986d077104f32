// The Gauss-Newton update shared by the tracker's point-to-plane refinements (AlignPointToPlane,
// RefineProjective): the normal equations of the residuals n . (R p + t - s) in the left update
// xi = (rotation, translation) of proxy_T_camera, plus a Gaussian prior on the deviation from the
// start pose.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "core/rigid3.h"

namespace mmh::track::internal {

// The prior's weight on each component of the deviation: (huber / sigma)^2, so that a direction
// the data leaves free is held at about sigma while a data residual of about `huber` counts one
// (0: no prior).
inline double PriorWeight(double huber, double sigma) {
  return sigma > 0 ? (huber / sigma) * (huber / sigma) : 0.0;
}

// The normal equations J^T W J xi = -J^T W r of point-to-plane residuals r = n . (s - m) (s the
// data point and m its model sample, in the model frame; J = [s x n, n]) with Huber weights,
// summed in float over blocks of 256 residuals (exact enough, and fast), then in double.
class NormalEquations {
 public:
  explicit NormalEquations(float huber) : huber_(huber) {}

  void Add(const Eigen::Vector3f& s, const Eigen::Vector3f& n, float residual) {
    const float a = std::abs(residual);
    AddWeighted(s, n, residual, a <= huber_ ? 1.0f : huber_ / a);
  }
  // With the weight w given (another robust kernel's).
  void AddWeighted(const Eigen::Vector3f& s, const Eigen::Vector3f& n, float residual, float w) {
    Eigen::Matrix<float, 6, 1> j;
    j.head<3>() = s.cross(n);
    j.tail<3>() = n;
    hf_.noalias() += (w * j) * j.transpose();
    gf_.noalias() += (w * residual) * j;
    ++used_;
    if (++block_ == 256) Flush();
  }

  // The sums so far (#6 by 6 and #6), and how many residuals they hold.
  const Eigen::Matrix<double, 6, 6>& h() {
    Flush();
    return h_;
  }
  const Eigen::Matrix<double, 6, 1>& g() {
    Flush();
    return g_;
  }
  int used() const { return used_; }

 private:
  void Flush() {
    h_ += hf_.cast<double>();
    g_ += gf_.cast<double>();
    hf_.setZero();
    gf_.setZero();
    block_ = 0;
  }

  float huber_;
  Eigen::Matrix<double, 6, 6> h_ = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> g_ = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<float, 6, 6> hf_ = Eigen::Matrix<float, 6, 6>::Zero();
  Eigen::Matrix<float, 6, 1> gf_ = Eigen::Matrix<float, 6, 1>::Zero();
  int used_ = 0, block_ = 0;
};

struct PoseUpdate {
  // Starts at proxy_T_camera, with the prior's standard deviations [rad] and [m] (0: none)
  // weighted against residuals of about `huber` [m].
  PoseUpdate(const Rigid3& proxy_T_camera, double huber, double prior_rotation_sigma,
             double prior_translation_sigma)
      : rotation(proxy_T_camera.rotation.normalized().toRotationMatrix()),
        translation(proxy_T_camera.translation),
        start_rotation(rotation),
        start_translation(translation),
        prior_rotation(PriorWeight(huber, prior_rotation_sigma)),
        prior_translation(PriorWeight(huber, prior_translation_sigma)) {}

  // proxy_T_camera being refined, and the start the prior holds it to.
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  Eigen::Matrix3d start_rotation;
  Eigen::Vector3d start_translation;
  double prior_rotation = 0.0;     // PriorWeight of the rotation [1/rad^2 scaled]
  double prior_translation = 0.0;  // PriorWeight of the translation

  // Solves H xi = -g (the equations with the prior) and applies exp(xi) on the left (a tiny
  // damping proportional to the residuals' count keeps a degenerate view, a single face, from a
  // wild step). Returns false, changing nothing, when the step is not finite; *angle and *shift
  // are the step's rotation [rad] and translation [m].
  bool Apply(NormalEquations& equations, double* angle, double* shift) {
    Eigen::Matrix<double, 6, 6> h = equations.h();
    Eigen::Matrix<double, 6, 1> g = equations.g();
    const int used = equations.used();
    if (prior_rotation > 0 || prior_translation > 0) {
      // The deviation from the start, log(T T_start^-1) to first order: a left update exp(xi) T
      // adds xi to it. Cost 1/2 (e + xi)^T W (e + xi): H += W, g += W e.
      const Eigen::Matrix3d deviation = rotation * start_rotation.transpose();
      const Eigen::AngleAxisd angle_axis(deviation);
      const Eigen::Vector3d e_r = angle_axis.angle() * angle_axis.axis();
      const Eigen::Vector3d e_t = translation - deviation * start_translation;
      for (int a = 0; a < 3; ++a) {
        h(a, a) += prior_rotation;
        g(a) += prior_rotation * e_r(a);
        h(3 + a, 3 + a) += prior_translation;
        g(3 + a) += prior_translation * e_t(a);
      }
    }
    h.diagonal().array() += 1e-9 * used;
    const Eigen::Matrix<double, 6, 1> xi = -h.ldlt().solve(g);
    if (!xi.allFinite()) return false;
    const Eigen::Vector3d omega = xi.head<3>();
    *angle = omega.norm();
    *shift = xi.tail<3>().norm();
    const Eigen::Matrix3d step = *angle > 0
                                     ? Eigen::AngleAxisd(*angle, omega / *angle).toRotationMatrix()
                                     : Eigen::Matrix3d::Identity();
    rotation = step * rotation;
    translation = step * translation + xi.tail<3>();
    return true;
  }
};

}  // namespace mmh::track::internal
