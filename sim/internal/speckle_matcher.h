// The structured-light sensor's two stages (docs/sensor.md, "Structured light"): the IR image of
// the projector's speckle pattern on the scene, and disparity by block matching that image
// against the reference pattern. Both run on the delivered depth image's pixel grid.
#pragma once

#include <cstdint>
#include <vector>

#include "sim/structured_light.h"

namespace mmh::sim::internal {

// Per-pixel geometry of the depth view (#width by #height, row-major).
struct SpeckleScene {
  const float* depth = nullptr;          // along the optical axis [m]; +inf where nothing was hit
  const float* disparity = nullptr;      // IR disparity f b / z [px]; 0 where nothing was hit
  const float* cos_incidence = nullptr;  // in [0, 1]
  const uint8_t* occluded = nullptr;     // hidden from the projector or the IR camera
  const float* ir_diffuse = nullptr;     // SurfaceMaterial: ir_albedo (1 - specularity)
  const float* ir_specular = nullptr;    // SurfaceMaterial: specularity
};

// How a matched disparity becomes a depth pixel (the Kinect's raw lattice, range, TUM units).
struct SpeckleOutput {
  float lattice = 0;  // s f b [px m]
  float raw_offset = 0;
  float subpixel_steps = 8;
  bool quantise = true;
  float min_depth = 0, max_depth = 0;
  float inverse_scale = 0;  // depth units per metre
};


class SpeckleMatcher {
 public:
  // The pattern for a width x height image whose disparities reach max_disparity [px] (larger
  // ones are matched as if at max_disparity and fail).
  SpeckleMatcher(const StructuredLightOptions& options, int width, int height,
                 double max_disparity);

  // The IR image (#width by #height, full scale 1, quantised), its sensor noise keyed by `key`
  // (counter-based: the same for any thread count).
  void RenderIr(const SpeckleScene& scene, uint32_t key, float* ir) const;
  // Depth from the IR image (0 = missing); `cause` (optional, #pixels) says why.
  void Match(const SpeckleScene& scene, const float* ir, const SpeckleOutput& output,
             uint16_t* depth, MissingCause* cause = nullptr) const;

  // The reference pattern at integer column x (>= x_min()) of row v, as matched.
  float Reference(int x, int v) const;
  // The pattern at sub-pixel column x of row v, as projected (linear between 1/8 px samples).
  float Pattern(float x, int v) const;
  int x_min() const { return x_min_; }

 private:
  void MatchRow(const SpeckleScene& scene, const float* ir, const SpeckleOutput& output, int v,
                const std::vector<int>& centre, uint16_t* depth, MissingCause* cause) const;

  StructuredLightOptions options_;
  int width_ = 0, height_ = 0;
  int radius_ = 0;       // window_px / 2
  int x_min_ = 0;        // first integer pattern column (negative: disparities shift left)
  int columns_ = 0;      // integer pattern columns
  int max_d_ = 0;        // largest integer disparity matched
  static constexpr int kSubsamples = 8;
  int samples_ = 0;      // pattern samples per row: columns_ * kSubsamples + 1
  std::vector<float> pattern_;    // #height by samples_
  std::vector<float> reference_;  // #height by columns_
  // Per row and integer column of the reference: window sum and 1 / norm (norm = sqrt of the
  // window's sum of squared deviations; 0 where it is 0).
  std::vector<float> reference_sum_;
  std::vector<float> reference_inverse_norm_;
};

}  // namespace mmh::sim::internal
