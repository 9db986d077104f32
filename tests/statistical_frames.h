// The frames the sensor's, tracker's and CLI tests' accuracy checks were written against, shared
// by tests/test_util.h and tests/track/sim_take.h (which the benchmarks include too, without gtest).
#pragma once

#include <string>
#include <vector>

namespace mmh::test_util {

// The frames the sensor's, tracker's and CLI tests' accuracy checks were written against: the
// statistical sensor with the camera at (0, -0.9, 0.75), 1.17 m from the play area, the defaults
// before issue 23 made them structured light at 0.85 m. As config assignments (Config::Set), the
// one list that tests/track/sim_take.h, the pipeline tests and the CLI tests use. Structured-light
// accuracy is checked by the tracker's structured-light tests and the regression baselines.
inline const std::vector<std::string>& StatisticalFrameSettings() {
  static const std::vector<std::string> settings = {"sensor.mode=\"statistical\"", "camera.y=-0.9",
                                                    "camera.z=0.75"};
  return settings;
}

// The tracker for those frames, which have no block matcher's bleed: no skin growth (the default 1
// only turns the proxy's pixels beside the gripping fingers into skin there, and some first
// detections tip into the half-turn twin; docs/tracker.md, "Both options on by default"). As a
// config assignment, for `mmh track --set` and Config::Set.
inline const std::string& StatisticalFramesTrackerSetting() {
  static const std::string setting = "tracker.segmentation.skin_grow_px=0";
  return setting;
}

}  // namespace mmh::test_util
