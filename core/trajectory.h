// A trajectory: one rigid pose per frame with its timestamp, e.g. camera_T_proxy over a take.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/rigid3.h"

namespace mmh {

struct Trajectory {
  // Seconds, strictly increasing. #frames entries.
  std::vector<double> timestamps;
  // #frames entries; poses[i] is the pose at timestamps[i].
  std::vector<Rigid3> poses;

  std::size_t size() const { return poses.size(); }
  bool empty() const { return poses.empty(); }
};

// Median frame period in seconds (robust to a dropped frame); 0 for fewer than 2 frames.
double MedianFramePeriod(const std::vector<double>& timestamps);

// Checks what every algorithm assumes: equal lengths, finite values, unit quaternions (to 1e-6),
// strictly increasing timestamps. `name` (a file path or "take 3") starts the error message.
void ValidateTrajectory(const Trajectory& trajectory, const std::string& name);

}  // namespace mmh
