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
  const double dot = std::min(1.0, std::abs(a.dot(b)));
  return 2.0 * std::acos(dot);
}

}  // namespace mmh
