#include "sim/structured_light.h"

#include <array>
#include <cmath>

#include "core/error.h"
#include "core/options.h"

namespace mmh::sim {
namespace {

constexpr std::array<std::pair<SensorMode, const char*>, 2> kSensorModeNames = {{
    {SensorMode::kStatistical, "statistical"},
    {SensorMode::kStructuredLight, "structured_light"},
}};

constexpr std::array<std::pair<SlantedWindows, const char*>, 3> kSlantedWindowsNames = {{
    {SlantedWindows::kOff, "off"},
    {SlantedWindows::kFirstOrder, "first_order"},
    {SlantedWindows::kSheared, "sheared"},
}};

}  // namespace

std::span<const std::pair<SensorMode, const char*>> EnumNames(SensorMode) {
  return kSensorModeNames;
}

std::span<const std::pair<SlantedWindows, const char*>> EnumNames(SlantedWindows) {
  return kSlantedWindowsNames;
}

void StructuredLightOptions::Validate(const std::string& prefix) const {
  if (!std::isfinite(dot_density) || dot_density <= 0 || dot_density > 1) {
    ThrowBadValue(prefix + ".dot_density", FormatNumber(dot_density),
                  "dots per pixel in (0, 1] (Kinect v1: about 0.11)");
  }
  if (!std::isfinite(dot_sigma_px) || dot_sigma_px < 0.2 || dot_sigma_px > 3) {
    ThrowBadValue(prefix + ".dot_sigma_px", FormatNumber(dot_sigma_px), "a dot size in [0.2, 3] px");
  }
  if (!std::isfinite(faint_dot_density) || faint_dot_density < 0 || faint_dot_density > 2) {
    ThrowBadValue(prefix + ".faint_dot_density", FormatNumber(faint_dot_density),
                  "faint dots per pixel in [0, 2] (0: none)");
  }
  if (!std::isfinite(faint_dot_brightness) || faint_dot_brightness <= 0 ||
      faint_dot_brightness > 1) {
    ThrowBadValue(prefix + ".faint_dot_brightness", FormatNumber(faint_dot_brightness),
                  "a fraction of the bright dots' brightness in (0, 1]");
  }
  RequirePositive(projector_power, prefix + ".projector_power");
  RequireNonNegative(ambient, prefix + ".ambient");
  RequireNonNegative(read_noise, prefix + ".read_noise");
  RequireNonNegative(shot_gain, prefix + ".shot_gain");
  if (adc_bits < 4 || adc_bits > 12) {
    ThrowBadValue(prefix + ".adc_bits", std::to_string(adc_bits),
                  "an integer in [4, 12] (the Kinect's IR camera: 10)");
  }
  if (!(specular_exponent >= 0 && specular_exponent <= 1000) ||
      specular_exponent != std::floor(specular_exponent)) {
    ThrowBadValue(prefix + ".specular_exponent", FormatNumber(specular_exponent),
                  "a whole exponent in [0, 1000]");
  }
  RequireNonNegative(specular_gain, prefix + ".specular_gain");
  if (window_px < 3 || window_px > 31 || window_px % 2 == 0) {
    ThrowBadValue(prefix + ".window_px", std::to_string(window_px), "an odd size in [3, 31] px");
  }
  // The block matcher sums window products of ADC counts in 32-bit integers (exact).
  const double largest = static_cast<double>(window_px) * window_px *
                         std::pow(static_cast<double>((1 << adc_bits) - 1), 2);
  if (largest > 2147483647.0) {
    ThrowBadValue(prefix + ".window_px", std::to_string(window_px),
                  "a window whose pixel count times (2^adc_bits - 1)^2 stays below 2^31 (adc_bits " +
                      std::to_string(adc_bits) + ")");
  }
  if (search_px < 1 || search_px > 16) {
    ThrowBadValue(prefix + ".search_px", std::to_string(search_px), "an integer in [1, 16] px");
  }
  if (!std::isfinite(min_correlation) || min_correlation < -1 || min_correlation > 1) {
    ThrowBadValue(prefix + ".min_correlation", FormatNumber(min_correlation),
                  "a correlation in [-1, 1]");
  }
  RequireNonNegative(min_contrast, prefix + ".min_contrast");
  if (!std::isfinite(ambiguity_ratio) || ambiguity_ratio <= 0 || ambiguity_ratio > 1) {
    ThrowBadValue(prefix + ".ambiguity_ratio", FormatNumber(ambiguity_ratio), "a ratio in (0, 1]");
  }
  if (slanted_windows != SlantedWindows::kOff && !parabola_subpixel) {
    // Without the sub-pixel fit the diagnostic reports the rendered disparity: nothing to refine.
    ThrowBadValue(prefix + ".slanted_windows", EnumName(slanted_windows),
                  "\"off\" with parabola_subpixel false");
  }
  if (!std::isfinite(registration_growth_px) || registration_growth_px < 0 ||
      registration_growth_px > 1) {
    ThrowBadValue(prefix + ".registration_growth_px", FormatNumber(registration_growth_px),
                  "a growth in [0, 1] px");
  }
}

}  // namespace mmh::sim
