// The Gauss-Newton update shared by the tracker's point-to-plane refinements (AlignPointToPlane,
// RefineProjective): the normal equations of the residuals n . (R p + t - s) in the left update
// xi = (rotation, translation) of proxy_T_camera, plus a Gaussian prior on the deviation from the
// start pose.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace mmh::track::internal {

// The prior's weight on each component of the deviation: (huber / sigma)^2, so that a direction
// the data leaves free is held at about sigma while a data residual of about `huber` counts one
// (0: no prior).
inline double PriorWeight(double huber, double sigma) {
  return sigma > 0 ? (huber / sigma) * (huber / sigma) : 0.0;
}

struct PoseUpdate {
  // proxy_T_camera being refined, and the start the prior holds it to.
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  Eigen::Matrix3d start_rotation;
  Eigen::Vector3d start_translation;
  double prior_rotation = 0.0;     // PriorWeight of the rotation [1/rad^2 scaled]
  double prior_translation = 0.0;  // PriorWeight of the translation

  // Solves H xi = -g (with the prior) and applies exp(xi) on the left. `used`: how many residuals
  // H holds (a tiny damping proportional to it keeps a degenerate view, a single face, from a
  // wild step). Returns false, changing nothing, when the step is not finite; *angle and *shift
  // are the step's rotation [rad] and translation [m].
  bool Apply(Eigen::Matrix<double, 6, 6> h, Eigen::Matrix<double, 6, 1> g, int used, double* angle,
             double* shift) {
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
