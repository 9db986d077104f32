// One RGB-D frame as a Kinect v1 driver delivers it: what the tracker gets, whether the frame comes
// from the simulator, a recorded folder or a real sensor.
#pragma once

#include <cstdint>
#include <vector>

#include "core/camera.h"
#include "core/rigid3.h"

namespace mmh {

// Metres per depth unit of the TUM RGB-D format (5000 units = 1 m).
inline constexpr double kTumDepthScale = 1.0 / 5000.0;

struct RgbdFrame {
  int index = 0;           // frame number in its stream, from 0
  double timestamp = 0.0;  // [s]
  // Depth image, #height by #width row-major, in units of depth_scale metres; 0 = missing.
  // Integer units in memory as on disk, so a frame read back from a TUM folder is bit-identical
  // to the one that was written and a tracker gives the same result on either.
  std::vector<uint16_t> depth;
  double depth_scale = kTumDepthScale;
  PinholeIntrinsics depth_intrinsics;
  // Colour image, #height by #width by 3 row-major, 8-bit sRGB, channel order R, G, B.
  std::vector<uint8_t> rgb;
  PinholeIntrinsics color_intrinsics;
  // Pose of the depth camera in the colour camera's frame: identity for registered depth (the
  // default, as the Kinect drivers deliver it).
  Rigid3 color_T_depth;

  double DepthMetres(int u, int v) const {
    return depth[static_cast<size_t>(v) * depth_intrinsics.width + u] * depth_scale;
  }
};

}  // namespace mmh
