// The Kinect v1 depth model (DESIGN.md, "Kinect v1 model"): disparity lattice, axial and lateral
// noise after Nguyen, Izadi and Lovell 2012, range limits, missing-data rules. Pure functions of
// the options; the renderer (kinect_sensor.h) applies them per pixel.
#pragma once

#include <cstdint>
#include <string>

#include "core/camera.h"

namespace mmh::sim {

// The structured-light geometry that fixes the depth values a Kinect v1 can report.
struct KinectCalibration {
  // Focal length of the IR camera [px]; with the baseline it sets the disparity d = f b / z.
  double ir_focal_length = 580.0;
  // IR camera to projector along the camera's +x axis [m].
  double baseline = 0.075;
  // Disparity is measured in 1/subpixel_steps px: the raw 11-bit value is
  // raw = raw_offset - subpixel_steps * f * b / z, an integer, so z = s f b / (raw_offset - raw)
  // and the depth step is dz = z^2 / (s f b) (about 2.9 mm at 1 m). raw_offset 1092.5 is the NYU
  // Depth V2 calibration (z = 351.3 / (1092.5 - raw)).
  int subpixel_steps = 8;
  double raw_offset = 1092.5;

  template <class V>
  void VisitFields(V& v) {
    v("ir_focal_length", ir_focal_length);
    v("baseline", baseline);
    v("subpixel_steps", subpixel_steps);
    v("raw_offset", raw_offset);
  }
  void Validate(const std::string& prefix) const;

  // s f b [px m]: z * (raw_offset - raw).
  double lattice_constant() const { return subpixel_steps * ir_focal_length * baseline; }
};

// Raw 11-bit value whose lattice depth is nearest to z in disparity (z > 0); may fall outside
// [0, 2046] for depths the sensor cannot report.
int RawFromDepth(double z, const KinectCalibration& calibration);
// Depth [m] of a raw value (raw < raw_offset).
double DepthFromRaw(int raw, const KinectCalibration& calibration);
// The invalid raw value of the 11-bit stream.
inline constexpr int kRawInvalid = 2047;
// Distance between adjacent lattice depths near z [m]: z^2 / (s f b).
double LatticeStep(double z, const KinectCalibration& calibration);

// Axial noise sigma_z [m] at depth z [m] and incidence angle theta [rad] between the viewing ray
// and the surface normal (Nguyen et al. 2012, eq. for 10-60 degrees, plus their grazing term
// beyond 60 degrees): 0.0012 + 0.0019 (z - 0.4)^2 + [theta > 60deg] 0.0001 / sqrt(z) *
// theta^2 / (pi/2 - theta)^2.
struct AxialNoiseModel {
  double constant = 0.0012;        // [m]
  double quadratic = 0.0019;       // [1/m]
  double quadratic_origin = 0.4;   // [m]
  double grazing = 0.0001;         // [m^1.5]
  double grazing_from_deg = 60.0;  // [deg]

  template <class V>
  void VisitFields(V& v) {
    v("constant", constant);
    v("quadratic", quadratic);
    v("quadratic_origin", quadratic_origin);
    v("grazing", grazing);
    v("grazing_from_deg", grazing_from_deg);
  }
  void Validate(const std::string& prefix) const;
  double Sigma(double z, double theta) const;
};

// Lateral noise sigma_L [px] = base + slope * theta / (pi/2 - theta) (Nguyen et al. 2012: 0.8 px
// and 0.035). It moves depth edges: a pixel beside a depth discontinuity takes its neighbour's
// depth when its offset rounds to that neighbour.
struct LateralNoiseModel {
  double base_px = 0.8;
  double slope_px = 0.035;

  template <class V>
  void VisitFields(V& v) {
    v("base_px", base_px);
    v("slope_px", slope_px);
  }
  void Validate(const std::string& prefix) const;
  double Sigma(double theta) const;
};

}  // namespace mmh::sim
