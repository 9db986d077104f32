#include "core/trajectory.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/resource_limits.h"

namespace mmh {

double MedianFramePeriod(const std::vector<double>& timestamps) {
  if (timestamps.size() < 2) return 0.0;
  std::vector<double> periods(timestamps.size() - 1);
  for (std::size_t i = 0; i + 1 < timestamps.size(); ++i) {
    periods[i] = timestamps[i + 1] - timestamps[i];
  }
  auto middle = periods.begin() + static_cast<std::ptrdiff_t>(periods.size() / 2);
  std::nth_element(periods.begin(), middle, periods.end());
  return *middle;
}

void ValidateTrajectory(const Trajectory& trajectory, const std::string& name) {
  if (trajectory.timestamps.size() != trajectory.poses.size()) {
    ThrowBadValue(name,
                  std::to_string(trajectory.timestamps.size()) + " timestamps for " +
                      std::to_string(trajectory.poses.size()) + " poses",
                  "one timestamp per pose");
  }
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    // Built only on error: this loop runs over every frame of every take.
    auto where = [&] { return name + ", frame " + std::to_string(i); };
    const Rigid3& pose = trajectory.poses[i];
    const double t = trajectory.timestamps[i];
    if (!std::isfinite(t))
      ThrowBadValue(where() + ", timestamp", FormatNumber(t), "a finite number");
    if (i > 0 && !(t > trajectory.timestamps[i - 1])) {
      ThrowBadValue(
          where() + ", timestamp", FormatNumber(t),
          "greater than the previous timestamp " + FormatNumber(trajectory.timestamps[i - 1]));
    }
    if (!pose.translation.allFinite() || !pose.rotation.coeffs().allFinite()) {
      ThrowBadValue(where(), "a non-finite pose value", "finite translation and quaternion");
    }
    for (int k = 0; k < 3; ++k) {
      if (std::abs(pose.translation[k]) > kMaxTranslationMetres) {
        ThrowBadValue(where() + ", t" + std::string(1, "xyz"[k]), FormatNumber(pose.translation[k]),
                      "a translation within +-1e6 m (kMaxTranslationMetres)");
      }
    }
    const double norm = pose.rotation.norm();
    if (std::abs(norm - 1.0) > 1e-6) {
      ThrowBadValue(where() + ", quaternion norm", FormatNumber(norm), "a unit quaternion");
    }
  }
}

}  // namespace mmh
