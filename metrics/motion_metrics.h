// How abruptly a motion changes from one frame to the next: the jumps a viewer sees at a montage's
// seams (paper, "Blending": transitions should not show), compared with the same quantities over
// the takes' own motion.
#pragma once

#include <span>
#include <vector>

#include "core/rigid3.h"

namespace mmh::metrics {

// Per frame t of a trajectory (#frames entries each; 0 where undefined, at the ends):
//   position[t]         = ‖p(t) − p(t−1)‖ [m]                     (a jump in position)
//   velocity[t]         = ‖v(t) − v(t−1)‖ [m/s], v(t) = (p(t+1) − p(t))·fps
//   angular_velocity[t] = ‖ω(t) − ω(t−1)‖ [deg/s], ω(t) the rotation vector of
//                          R(t+1) R(t)ᵀ times fps (world frame)
struct MotionChanges {
  std::vector<double> position;
  std::vector<double> velocity;
  std::vector<double> angular_velocity;
};
MotionChanges ComputeMotionChanges(std::span<const Rigid3> poses, double fps);

// The largest value of `values` within [centre − radius, centre + radius] (clamped to the range).
double WindowMax(std::span<const double> values, int centre, int radius);

}  // namespace mmh::metrics
