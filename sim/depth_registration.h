// Depth measured in one camera's image carried into another camera's image: the registration of
// the Kinect's depth (measured by block matching in the IR camera's image) to its colour camera,
// as the device's driver does it. Each source pixel is a small fronto-parallel square at its
// depth; its four corners, moved into the destination camera and projected, span a footprint
// there, and every destination pixel whose centre lies in the footprint takes the point's depth
// in the destination camera, the nearest where footprints overlap (a z-buffer). So a near surface
// covers what lies behind it where it moves over it, a gap opens where it moves away (the far
// surface the IR camera did not see), and planes stay whole whatever the two focal lengths.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/rigid3.h"

namespace mmh::sim {

struct DepthRegistrationOptions {
  // Each footprint grown by this many destination pixels on every side before it is filled
  // (0: the exact footprint). A driver that splats each source pixel onto a fixed block of a
  // finer grid widens near surfaces by about this much.
  double footprint_growth_px = 0.0;

  void Validate(const std::string& prefix) const;
};

// `depth_m`: from.width x from.height row-major [m], 0 or NaN = missing; `to_T_from`: the source
// camera's pose in the destination camera's frame. Returns to.width x to.height depths [m] in the
// destination camera (0 = no source pixel covers it). `source` (optional): per destination pixel
// the index of the source pixel whose depth it took (-1: none).
std::vector<float> RegisterDepth(const std::vector<float>& depth_m, const PinholeIntrinsics& from,
                                 const PinholeIntrinsics& to, const Rigid3& to_T_from,
                                 const DepthRegistrationOptions& options = {},
                                 std::vector<int32_t>* source = nullptr);

}  // namespace mmh::sim
