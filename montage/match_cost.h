// C_match of eq. 5: the distance between two poses A1 = (q1, x1) and A2 = (q2, x2),
//   C_match(A1, A2) = ||q1 - q2||_2 + lambda ||x1 - x2||_2,
// with the quaternion sign resolved as DESIGN.md decides: q and -q are the same rotation, so the
// rotation term is min(||q1 - q2||, ||q1 + q2||). Computed from the differences (not from
// 2 - 2|q1.q2|) so that nearly equal rotations keep full relative precision.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/rigid3.h"

namespace mmh::montage {

// The one formula every kernel uses (scalar and vectorised loops call this inline), so that all of
// them round identically.
inline double MatchCost(double ax, double ay, double az, double aw, double atx, double aty,
                        double atz, double bx, double by, double bz, double bw, double btx,
                        double bty, double btz, double lambda) {
  const double dx = ax - bx, dy = ay - by, dz = az - bz, dw = aw - bw;
  const double sx = ax + bx, sy = ay + by, sz = az + bz, sw = aw + bw;
  const double minus = dx * dx + dy * dy + dz * dz + dw * dw;
  const double plus = sx * sx + sy * sy + sz * sz + sw * sw;
  const double ex = atx - btx, ey = aty - bty, ez = atz - btz;
  return std::sqrt(std::min(minus, plus)) + lambda * std::sqrt(ex * ex + ey * ey + ez * ez);
}

inline double MatchCost(const Rigid3& a, const Rigid3& b, double lambda) {
  const auto& qa = a.rotation;
  const auto& qb = b.rotation;
  const auto& ta = a.translation;
  const auto& tb = b.translation;
  return MatchCost(qa.x(), qa.y(), qa.z(), qa.w(), ta.x(), ta.y(), ta.z(), qb.x(), qb.y(), qb.z(),
                   qb.w(), tb.x(), tb.y(), tb.z(), lambda);
}

}  // namespace mmh::montage
