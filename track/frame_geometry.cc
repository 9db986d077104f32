#include "track/internal/frame_geometry.h"

#include <algorithm>
#include <cmath>

namespace mmh::track::internal {

bool ColorRegisteredToDepth(const RgbdFrame& frame) {
  const PinholeIntrinsics& k = frame.depth_intrinsics;
  return frame.depth.size() == static_cast<size_t>(k.pixel_count()) &&
         frame.rgb.size() == static_cast<size_t>(3 * k.pixel_count()) &&
         frame.color_intrinsics == k && frame.color_T_depth.translation.norm() < 1e-9 &&
         std::abs(std::abs(frame.color_T_depth.rotation.w()) - 1) < 1e-12;
}

std::optional<ImageRect> ProjectTableBox(const Eigen::Vector3d& table_min,
                                         const Eigen::Vector3d& table_max,
                                         const Rigid3& camera_T_table,
                                         const PinholeIntrinsics& intrinsics) {
  double u0 = 1e300, v0 = 1e300, u1 = -1e300, v1 = -1e300;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d table_p((c & 1) ? table_max.x() : table_min.x(),
                                  (c & 2) ? table_max.y() : table_min.y(),
                                  (c & 4) ? table_max.z() : table_min.z());
    const Eigen::Vector3d camera_p = camera_T_table * table_p;
    if (camera_p.z() < 0.05) return std::nullopt;
    const Eigen::Vector2d uv = intrinsics.Project(camera_p);
    u0 = std::min(u0, uv.x());
    v0 = std::min(v0, uv.y());
    u1 = std::max(u1, uv.x());
    v1 = std::max(v1, uv.y());
  }
  ImageRect rect;
  rect.x0 = std::clamp(static_cast<int>(std::floor(u0)), 0, intrinsics.width);
  rect.y0 = std::clamp(static_cast<int>(std::floor(v0)), 0, intrinsics.height);
  rect.x1 = std::clamp(static_cast<int>(std::ceil(u1)) + 1, 0, intrinsics.width);
  rect.y1 = std::clamp(static_cast<int>(std::ceil(v1)) + 1, 0, intrinsics.height);
  return rect;
}

}  // namespace mmh::track::internal
