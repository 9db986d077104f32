#include "core/rigid3.h"

#include <algorithm>
#include <cmath>

namespace mmh {

Rigid3 Interpolate(const Rigid3& from, const Rigid3& to, double weight) {
  // Eigen's slerp already takes the shorter arc (it flips the sign when the dot product is < 0).
  return Rigid3(from.rotation.slerp(weight, to.rotation).normalized(),
                (1.0 - weight) * from.translation + weight * to.translation);
}

double RotationAngle(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  // 2 atan2(|v|, |w|) of a^-1 b keeps full precision for tiny angles (2 acos(|a.b|) does not).
  const Eigen::Quaterniond d = a.conjugate() * b;
  return 2.0 * std::atan2(d.vec().norm(), std::abs(d.w()));
}

Eigen::Vector3d RotationVector(Eigen::Quaterniond q) {
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const Eigen::AngleAxisd aa(q);
  return aa.axis() * aa.angle();
}

}  // namespace mmh
