#include "sim/kinect_model.h"

#include <cmath>
#include <numbers>

#include "core/error.h"

namespace mmh::sim {
void KinectCalibration::Validate(const std::string& prefix) const {
  RequirePositive(ir_focal_length, prefix + ".ir_focal_length", "px");
  RequirePositive(baseline, prefix + ".baseline", "m");
  if (subpixel_steps < 1 || subpixel_steps > 64) {
    ThrowBadValue(prefix + ".subpixel_steps", std::to_string(subpixel_steps),
                  "an integer in [1, 64] (Kinect v1: 8)");
  }
  if (!std::isfinite(raw_offset) || raw_offset <= 0 || raw_offset > 4096) {
    ThrowBadValue(prefix + ".raw_offset", FormatNumber(raw_offset),
                  "a number in (0, 4096] raw units (NYU calibration: 1092.5)");
  }
}

int RawFromDepth(double z, const KinectCalibration& calibration) {
  return static_cast<int>(std::lround(calibration.raw_offset - calibration.lattice_constant() / z));
}

double DepthFromRaw(int raw, const KinectCalibration& calibration) {
  return calibration.lattice_constant() / (calibration.raw_offset - raw);
}

double LatticeStep(double z, const KinectCalibration& calibration) {
  return z * z / calibration.lattice_constant();
}

void AxialNoiseModel::Validate(const std::string& prefix) const {
  RequireNonNegative(constant, prefix + ".constant", "m");
  RequireNonNegative(quadratic, prefix + ".quadratic", "1/m");
  RequireNonNegative(quadratic_origin, prefix + ".quadratic_origin", "m");
  RequireNonNegative(grazing, prefix + ".grazing", "m^1.5");
  if (!std::isfinite(grazing_from_deg) || grazing_from_deg < 0 || grazing_from_deg >= 90) {
    ThrowBadValue(prefix + ".grazing_from_deg", FormatNumber(grazing_from_deg),
                  "an angle in [0, 90) degrees");
  }
}

double AxialNoiseModel::Sigma(double z, double theta) const {
  const double dz = z - quadratic_origin;
  double sigma = constant + quadratic * dz * dz;
  if (theta > grazing_from_deg * std::numbers::pi / 180.0) {
    const double rest = std::max(std::numbers::pi / 2 - theta, 1e-6);
    sigma += grazing / std::sqrt(z) * theta * theta / (rest * rest);
  }
  return sigma;
}

void LateralNoiseModel::Validate(const std::string& prefix) const {
  RequireNonNegative(base_px, prefix + ".base_px", "px");
  RequireNonNegative(slope_px, prefix + ".slope_px", "px");
}

double LateralNoiseModel::Sigma(double theta) const {
  const double rest = std::max(std::numbers::pi / 2 - theta, 1e-6);
  return base_px + slope_px * theta / rest;
}

}  // namespace mmh::sim
