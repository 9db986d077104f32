// Rigid transforms named by their frames (Sophus style): a_T_b maps coordinates in frame b to
// coordinates in frame a, and a_T_c = a_T_b * b_T_c. See docs/notation.md.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace mmh {

struct Rigid3 {
  // Unit quaternion; q and -q are the same rotation.
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  // Translation in metres.
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3() = default;
  Rigid3(const Eigen::Quaterniond& q, const Eigen::Vector3d& t) : rotation(q), translation(t) {}

  static Rigid3 Identity() { return Rigid3(); }

  // a_T_c = a_T_b * b_T_c.
  Rigid3 operator*(const Rigid3& b_T_c) const {
    return Rigid3(rotation * b_T_c.rotation, rotation * b_T_c.translation + translation);
  }
  // Maps a point given in the right-hand frame into the left-hand frame.
  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const {
    return rotation * point + translation;
  }
  // b_T_a from a_T_b.
  Rigid3 Inverse() const {
    const Eigen::Quaterniond inverse_rotation = rotation.conjugate();
    return Rigid3(inverse_rotation, -(inverse_rotation * translation));
  }
};

// Linear interpolation of the translations and spherical linear interpolation of the rotations
// (Shoemake 1985) along the shorter arc; weight 0 gives `from`, 1 gives `to`.
Rigid3 Interpolate(const Rigid3& from, const Rigid3& to, double weight);

// An angle [rad] wrapped into [-pi, pi].
inline double WrapAngle(double angle) { return std::remainder(angle, 2 * 3.14159265358979323846); }

// Angle of the rotation from a to b in radians, in [0, pi].
double RotationAngle(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b);

// The rotation vector of a unit quaternion: axis times angle, along the shorter arc (angle in
// [0, pi]).
Eigen::Vector3d RotationVector(Eigen::Quaterniond q);

}  // namespace mmh
