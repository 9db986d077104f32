// The sensor's options in the statistical mode, for the sensor tests written against its per-pixel
// rules (the default mode is structured light since issue 23).
#pragma once

#include "sim/kinect_sensor.h"

namespace mmh::sim::test_modes {

inline KinectSensorOptions Statistical() {
  KinectSensorOptions options;
  options.mode = SensorMode::kStatistical;
  return options;
}

}  // namespace mmh::sim::test_modes
