// The sensor's options checked (sim/kinect_sensor.h), apart from the sensor so that a program
// that only reads configs (the light mmh: docs/architecture.md, "Start-up") links no renderer
// (Embree).
#include <cmath>
#include <string>

#include "core/error.h"
#include "sim/kinect_sensor.h"

namespace mmh::sim {

void ColorModel::Validate(const std::string& prefix) const {
  const double norm = std::sqrt(light_x * light_x + light_y * light_y + light_z * light_z);
  if (!std::isfinite(norm) || norm == 0) {
    ThrowBadValue(prefix + ".light_x/y/z",
                  "(" + FormatNumber(light_x) + ", " + FormatNumber(light_y) + ", " +
                      FormatNumber(light_z) + ")",
                  "a finite non-zero direction");
  }
  RequireNonNegative(ambient, prefix + ".ambient");
  RequireNonNegative(diffuse, prefix + ".diffuse");
  if (background_gray < 0 || background_gray > 255) {
    ThrowBadValue(prefix + ".background_gray", std::to_string(background_gray),
                  "an 8-bit value in [0, 255]");
  }
  RequireNonNegative(read_noise, prefix + ".read_noise", "(8-bit units)");
  RequireNonNegative(shot_gain, prefix + ".shot_gain", "(8-bit units)");
}

void MissingDataModel::Validate(const std::string& prefix) const {
  RequireNonNegative(edge_jump_px, prefix + ".edge_jump_px", "px");
  RequireProbability(edge_probability, prefix + ".edge_probability");
  if (!std::isfinite(grazing_from_deg) || !std::isfinite(grazing_to_deg) || grazing_from_deg < 0 ||
      grazing_to_deg > 90 || grazing_from_deg >= grazing_to_deg) {
    ThrowBadValue(prefix + ".grazing_from_deg/grazing_to_deg",
                  FormatNumber(grazing_from_deg) + " / " + FormatNumber(grazing_to_deg),
                  "0 <= from < to <= 90 degrees");
  }
  RequireProbability(speckle_probability, prefix + ".speckle_probability");
}

void KinectSensorOptions::Validate(const std::string& prefix) const {
  intrinsics.Validate(prefix + ".intrinsics");
  ir_intrinsics.Validate(prefix + ".ir_intrinsics");
  if (!std::isfinite(ir_camera_offset) || std::abs(ir_camera_offset) > 1.0) {
    ThrowBadValue(prefix + ".ir_camera_offset", FormatNumber(ir_camera_offset),
                  "an offset in [-1, 1] m (Kinect v1: 0.025)");
  }
  calibration.Validate(prefix + ".calibration");
  if (!std::isfinite(min_depth) || min_depth <= 0) {
    ThrowBadValue(prefix + ".min_depth", FormatNumber(min_depth), "a depth > 0 m");
  }
  if (!std::isfinite(max_depth) || max_depth <= min_depth || max_depth > 13.0) {
    ThrowBadValue(prefix + ".max_depth", FormatNumber(max_depth),
                  "a depth above min_depth (" + FormatNumber(min_depth) +
                      " m) and at most 13 m (65535 depth units)");
  }
  axial.Validate(prefix + ".axial");
  lateral.Validate(prefix + ".lateral");
  missing.Validate(prefix + ".missing");
  color.Validate(prefix + ".color");
  structured_light.Validate(prefix + ".structured_light");
  if (structured_light.lattice_search && calibration.subpixel_steps != 8) {
    ThrowBadValue(prefix + ".structured_light.lattice_search", "true",
                  "false with calibration.subpixel_steps " +
                      std::to_string(calibration.subpixel_steps) +
                      " (the search shifts the pattern by its 1/8 px samples)");
  }
  if (!std::isfinite(frame_rate) || frame_rate <= 0 || frame_rate > 1000) {
    ThrowBadValue(prefix + ".frame_rate", FormatNumber(frame_rate), "a rate in (0, 1000] Hz");
  }
}

}  // namespace mmh::sim
