// Small image-geometry helpers shared by the segmentation and the slider reader.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "core/rgbd_frame.h"
#include "core/rigid3.h"
#include "track/segmentation.h"

namespace mmh::track::internal {

// True when the frame's colour image is registered to its depth image (same intrinsics, identity
// color_T_depth) and both have the intrinsics' size: then colour and depth share pixels.
bool ColorRegisteredToDepth(const RgbdFrame& frame);

// The image rectangle (clipped to the image) of the axis-aligned box [min, max] given in the table
// frame, seen by a camera with `intrinsics` at camera_T_table; nullopt when a corner is closer
// than 5 cm to the camera plane or behind it.
std::optional<ImageRect> ProjectTableBox(const Eigen::Vector3d& table_min,
                                         const Eigen::Vector3d& table_max,
                                         const Rigid3& camera_T_table,
                                         const PinholeIntrinsics& intrinsics);

}  // namespace mmh::track::internal
