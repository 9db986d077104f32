// TablePlaneOptions checked (track/table_plane.h), apart from the plane's RANSAC (PCL): see
// track/proxy_tracker_options.cc.
#include <string>

#include "core/error.h"
#include "track/table_plane.h"

namespace mmh::track {

void TablePlaneOptions::Validate(const std::string& prefix) const {
  if (pixel_step < 1 || pixel_step > 64) {
    ThrowBadValue(prefix + ".pixel_step", std::to_string(pixel_step), "an integer in [1, 64]");
  }
  RequirePositive(distance_threshold, prefix + ".distance_threshold", "m");
  if (max_iterations < 1) {
    ThrowBadValue(prefix + ".max_iterations", std::to_string(max_iterations), ">= 1");
  }
  if (max_planes < 1 || max_planes > 10) {
    ThrowBadValue(prefix + ".max_planes", std::to_string(max_planes), "an integer in [1, 10]");
  }
  RequireProbability(min_inlier_share, prefix + ".min_inlier_share");
  RequirePositive(max_calibration_angle_deg, prefix + ".max_calibration_angle_deg", "deg");
  RequirePositive(max_calibration_distance, prefix + ".max_calibration_distance", "m");
  RequirePositive(up_tolerance_deg, prefix + ".up_tolerance_deg", "deg");
}

}  // namespace mmh::track
