// The published depth-noise models issue 23 names as anchors "to learn from and beat", in our own
// implementation from their descriptions, applied to an exact depth image so that `mmh
// sensor-check` sets their realism beside the structured-light mode's (docs/sensor.md, "The
// anchors"). Per-pixel models (Nguyen et al. 2012) are the statistical mode itself; these two are
// the ones a renderer-plus-post-process pipeline uses:
//  - ICL-NUIM (Handa, Whelan, McDonald, Davison, ICRA 2014): every pixel moved by a Gaussian shift
//    (sigma 1/2 px in u and v, the depth bilinearly interpolated there), then the noise of Barron
//    and Malik (CVPR 2013) in the Kinect's raw disparity units: with z_c = 100 z [cm],
//      z' = 35130 / round(35130 / z_c + n / 6 + 1/2) cm,  n ~ N(0, 1),
//    (35130 / z_c = 351.3 / z, the NYU calibration's raw-disparity distance: 1092.5 - raw).
//  - simkinect (Handa's public companion code of ICL-NUIM, with the filter of Bohg, Romero,
//    Herzog, Schaal, ICRA 2014): the same shift; disparity d = f b / z rounded to 1/8 px; a window
//    filter over a binary dot pattern (below); depth f b / d; then the Barron-Malik noise above
//    with z_c rounded to whole centimetres first, as the code does (its scale factor 100; terraces
//    of 1 cm, coarser than the Kinect's own 1 mm lattice step at 0.6 m).
//    The filter, for every pixel that holds a dot, over the window_px x window_px window around it:
//    the dots on valid pixels must be more than valid_share of the window's dots; the window's
//    valid disparities give a mean; a pixel is an inlier where |d - mean| / max(1, 1.44 r^2) <
//    inlier_px (r: its distance from the centre [px]); if the dots on inliers again exceed
//    valid_share of the dots, the centre keeps its disparity (rounded to 1/8 px) and passes it to
//    the pixels within fill_radius_px that no nearer centre has filled (weight 1 / (1 + r^2), the
//    larger weight wins, the first in row-major order on ties). Every other pixel is missing.
// Inputs and outputs are depth [m], width x height row-major, 0 = missing. Noise comes from the
// sensor's counter-based generator keyed by (seed, frame): the same bytes for any thread count.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace mmh::sim {

enum class AnchorModel { kIclNuim, kSimKinect };

// "ICL-NUIM", "simkinect".
std::string AnchorName(AnchorModel model);

struct AnchorNoiseOptions {
  double shift_sigma_px = 0.5;       // the lateral Gaussian shift in u and v (both models)
  double raw_noise_sigma = 1.0 / 6;  // Barron and Malik's disparity noise [raw units, 1/8 px]
  double focal_px = 580;             // simkinect's disparity f b / z: the sensor's IR focal length
  double baseline_m = 0.075;         // ... and baseline
  // simkinect's filter (Bohg et al. 2014's values).
  int window_px = 9;
  double valid_share = 1 / 1.2;
  double inlier_px = 0.1;
  int fill_radius_px = 3;
  // The filter's dot pattern: a pixel holds a dot with this probability (0.11: the Kinect's about
  // 34 000 dots over its 640 x 480 image; simkinect tiles an image of the real pattern, which we
  // do not have), drawn by the counter-based hash keyed by dot_seed.
  double dot_density = 0.11;
  uint64_t dot_seed = 20100604;
  void Validate(const std::string& prefix) const;
};

// The model applied to `exact_m` (width x height, metres, 0 = missing). A bilinear neighbour that
// is missing makes the shifted pixel missing. InputError (exit code 2) for a size mismatch or bad
// options.
std::vector<float> ApplyAnchorNoise(AnchorModel model, const std::vector<float>& exact_m, int width,
                                    int height, uint64_t seed, int frame,
                                    const AnchorNoiseOptions& options = {});

}  // namespace mmh::sim
