// The structured-light mode of the synthetic Kinect (docs/sensor.md, "Structured light"): the
// projector's speckle pattern on the scene, the IR image it makes, and disparity by correlating
// windows of that image with the reference pattern, as the device computes it. Edge fattening,
// patchy errors and holes on dark, specular, grazing, thin and far surfaces follow from the
// image and the matching, not from per-effect rules.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <utility>

namespace mmh::sim {

// How the sensor turns geometry into depth (config `sensor.mode`).
enum class SensorMode {
  // The per-pixel model of docs/sensor.md (Nguyen et al. 2012 noise, edge and grazing rules):
  // fast; the default until 2026-11-29 (docs/sensor.md: what each mode costs, when to use which).
  kStatistical,
  // Speckle pattern, IR image and block matching (StructuredLightOptions).
  kStructuredLight,
};
std::span<const std::pair<SensorMode, const char*>> EnumNames(SensorMode);

// Why a pixel has no depth in the structured-light mode (KinectSensor::missing_causes).
enum class MissingCause : uint8_t {
  kValid = 0,
  kBorder,        // the window leaves the image
  kNothing,       // nothing hit (beyond everything)
  kShadow,        // hidden from the projector (IR shadow) or from the IR camera
  kLowSignal,     // window contrast below min_contrast
  kNoMatch,       // correlation below min_correlation, or the peak at the search range's end
  kAmbiguous,     // a second peak nearly as good
  kRange,         // outside the lattice or [min_depth, max_depth]
};

// StructuredLightOptions::slanted_windows (config names "off", "first_order", "sheared").
enum class SlantedWindows {
  kOff,  // the first match's disparity
  // The first match's disparity minus g . c, c from the reference pattern at that disparity (its
  // squared horizontal derivative's centroid under the window, tabulated per row, column and
  // 1/8 px phase): the sheared match to first order, at a table lookup per pixel.
  kFirstOrder,
  // The window matched again against the pattern sheared by g (window pixel (i, j) against the
  // pattern at column u + i - d - g_u i - g_v j, linear between its 1/8 px samples), the peak's
  // three-point Gaussian fit: exact, and slow (about 0.27 s of CPU a frame; bench/README.md).
  kSheared,
};
std::span<const std::pair<SlantedWindows, const char*>> EnumNames(SlantedWindows);

struct StructuredLightOptions {
  // The speckle pattern, fixed per device: dots at random positions (density per IR pixel; the
  // Kinect v1 projects about 34 000 dots, 0.11 per pixel of its 640 x 480 image), each a Gaussian
  // of dot_sigma_px (optics and pixel blur) with a brightness uniform in [0.5, 1].
  double dot_density = 0.11;
  double dot_sigma_px = 0.6;
  uint64_t pattern_seed = 20100604;
  // A second population of faint dots between the bright ones (0: none), of the same size, each
  // of faint_dot_brightness times a brightness uniform in [0.5, 1]: a texture denser than the
  // bright dots under each window, which sets how far a match on a slanted surface strays from the
  // window's centre (docs/sensor.md, "Small patches like for like").
  double faint_dot_density = 0.0;
  double faint_dot_brightness = 0.2;
  // The IR image, full scale 1: a dot of brightness 1 on a white Lambertian surface facing the
  // camera at 1 m peaks at projector_power (fall-off 1 / z^2), ambient IR light reflected by the
  // surface adds ambient * albedo; sensor noise sigma^2 = read_noise^2 + shot_gain * value;
  // values clip at full scale and are quantised to adc_bits (at most 12; window_px^2 (2^adc_bits -
  // 1)^2 below 2^31: the matcher's sums are exact 32-bit integers).
  double projector_power = 0.6;
  double ambient = 0.02;
  double read_noise = 0.004;
  double shot_gain = 0.002;
  int adc_bits = 10;
  // Glare, the mirror lobe of SurfaceMaterial::specularity: specular_gain cos^n(theta), n =
  // specular_exponent (whole), without the dots (a mirror shows the projector's aperture, not
  // the pattern on its surface): near normal incidence it floods the window, the match fails.
  double specular_exponent = 40.0;
  double specular_gain = 8.0;
  // Block matching: window of window_px square (odd) against the reference pattern, at integer
  // disparities within search_px of the rendered disparities under the window (the device
  // searches its whole range; the truth is known here, so only the candidates that can win are
  // scored), refined by a parabola through the peak and its neighbours, reported on the
  // 1/subpixel_steps lattice. Rejected: normalised correlation below min_correlation, window
  // contrast (standard deviation) below min_contrast (low signal), a second peak at least two
  // pixels away scoring above ambiguity_ratio times the best, or a peak on the search range's end.
  int window_px = 9;
  int search_px = 2;
  double min_correlation = 0.55;
  double min_contrast = 0.005;
  double ambiguity_ratio = 0.95;
  // Diagnostics (docs/tracker.md, "Structured-light frames"), both true on a real device:
  // edge_candidates false searches only around the disparity at the window's centre (no edge
  // fattening from the sides' surfaces); parabola_subpixel false reports the rendered disparity
  // where the integer match lies within a pixel of it (no pixel locking, no sub-pixel noise; the
  // integer match, its rejections and the matches to other surfaces stay).
  bool edge_candidates = true;
  bool parabola_subpixel = true;
  // Sub-pixel disparity by correlating against the reference shifted by the raw lattice values
  // (1/8 px) near the Gaussian fit (a climb to the best, within a pixel of the integer match)
  // instead of taking the fit itself (docs/sensor.md, "Sub-pixel search on the lattice"). Its
  // per-pixel search costs about 6 times the IR image and matching step; requires
  // subpixel_steps 8 (the pattern's sampling).
  bool lattice_search = false;
  // How a match on a slanted surface is refined (docs/sensor.md, "Slanted windows"). On a
  // surface whose disparity changes across the window by (g_u, g_v) [px/px], a match of the
  // window as one disparity strays from the centre's by g . c, c the centroid of the pattern's
  // horizontal detail under the window (about |g| / sqrt(12 rho) px, rho dots per pixel, whatever
  // the window's size). A plane fitted to the first match's disparities under the window gives g.
  // Requires parabola_subpixel (validated). First order by default since 2026-12-02: off leaves
  // the real Xtion's small patches 1.66 times as noisy in the model (docs/sensor.md).
  SlantedWindows slanted_windows = SlantedWindows::kFirstOrder;
  // Match windows centred in the projector's shadow like any other, so that the correlation
  // decides (a window whose lit part correlates keeps its depth, as on the device, which does not
  // know where the shadow is; docs/sensor.md, "The step law of the bands"); false rejects them
  // outright (the model's rule until 2026-12-01; the real desk's edge keeps depth inside the
  // geometric shadow: docs/sensor.md, "Matching in the shadow becomes the default").
  bool match_in_shadow = true;
  // With registered depth: render the IR image and match it on the IR camera's own grid
  // (ir_intrinsics, 2.5 cm beside the colour camera), then carry the depth to the colour camera's
  // image as the device's driver does (sim/depth_registration.h: each IR pixel's footprint, the
  // nearest surface where they overlap), instead of matching on the delivered grid. The IR
  // camera's occlusion then comes from the registration, and the object's outline bleeds as the
  // real frames' does (docs/sensor.md, "Matched on the IR camera's grid"). Costs a second view's
  // casts.
  bool match_on_ir_grid = true;
  // With match_on_ir_grid: each IR pixel's footprint grown by this many colour pixels on every
  // side before the registration fills it (DepthRegistrationOptions::footprint_growth_px). Where
  // the depth steps by one lattice value between neighbouring IR pixels their footprints part by
  // f_colour t / (8 f_ir b) = 525 * 0.025 / (8 * 580 * 0.075) = 0.038 px at every range, and a
  // colour pixel whose centre falls in that gap gets no depth: pinholes along the lattice's
  // iso-depth lines that real registered frames do not show. 0.05 closes gaps of up to two
  // lattice steps (docs/sensor.md, "Pinholes of the registration").
  double registration_growth_px = 0.05;

  template <class V>
  void VisitFields(V& v) {
    v("dot_density", dot_density);
    v("dot_sigma_px", dot_sigma_px);
    v("pattern_seed", pattern_seed);
    v("faint_dot_density", faint_dot_density);
    v("faint_dot_brightness", faint_dot_brightness);
    v("projector_power", projector_power);
    v("ambient", ambient);
    v("read_noise", read_noise);
    v("shot_gain", shot_gain);
    v("adc_bits", adc_bits);
    v("specular_exponent", specular_exponent);
    v("specular_gain", specular_gain);
    v("window_px", window_px);
    v("search_px", search_px);
    v("min_correlation", min_correlation);
    v("min_contrast", min_contrast);
    v("ambiguity_ratio", ambiguity_ratio);
    v("edge_candidates", edge_candidates);
    v("parabola_subpixel", parabola_subpixel);
    v("lattice_search", lattice_search);
    v("slanted_windows", slanted_windows);
    v("match_in_shadow", match_in_shadow);
    v("match_on_ir_grid", match_on_ir_grid);
    v("registration_growth_px", registration_growth_px);
  }
  void Validate(const std::string& prefix) const;
};

}  // namespace mmh::sim
