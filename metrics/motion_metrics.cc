#include "metrics/motion_metrics.h"

#include <Eigen/Geometry>
#include <algorithm>

namespace mmh::metrics {

MotionChanges ComputeMotionChanges(std::span<const Rigid3> poses, double fps) {
  const int n = static_cast<int>(poses.size());
  MotionChanges c;
  c.position.assign(n, 0.0);
  c.velocity.assign(n, 0.0);
  c.angular_velocity.assign(n, 0.0);
  std::vector<Eigen::Vector3d> v(std::max(n - 1, 0)), w(std::max(n - 1, 0));
  for (int t = 0; t + 1 < n; ++t) {
    v[t] = (poses[t + 1].translation - poses[t].translation) * fps;
    const Eigen::AngleAxisd step(poses[t + 1].rotation * poses[t].rotation.conjugate());
    w[t] = step.axis() * step.angle() * fps;
  }
  constexpr double kDegrees = 180.0 / 3.14159265358979323846;
  for (int t = 1; t < n; ++t) {
    c.position[t] = (poses[t].translation - poses[t - 1].translation).norm();
    if (t + 1 < n) {
      c.velocity[t] = (v[t] - v[t - 1]).norm();
      c.angular_velocity[t] = (w[t] - w[t - 1]).norm() * kDegrees;
    }
  }
  return c;
}

double WindowMax(std::span<const double> values, int centre, int radius) {
  const int n = static_cast<int>(values.size());
  const int first = std::clamp(centre - radius, 0, std::max(n - 1, 0));
  const int last = std::clamp(centre + radius, 0, std::max(n - 1, 0));
  double best = 0.0;
  for (int t = first; t <= last && t < n; ++t) best = std::max(best, values[t]);
  return best;
}

}  // namespace mmh::metrics
