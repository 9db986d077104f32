// Small statistics shared by the sensor checks (sim/sensor_check.cc, sim/error_structure.cc).
#pragma once

#include <cmath>
#include <vector>

namespace mmh::sim::internal {

// The median of a copy of `values` (NaN when empty); the mean of the two middle values for an
// even count.
double Median(std::vector<double> values);

// A depth reading [m]: finite and positive (0 and NaN mark missing pixels).
inline bool ValidDepth(float z) { return std::isfinite(z) && z > 0; }

}  // namespace mmh::sim::internal
