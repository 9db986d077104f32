// The structured-light sensor's two stages (docs/sensor.md, "Structured light"): the IR image of
// the projector's speckle pattern on the scene, and disparity by block matching that image
// against the reference pattern. Both run on the delivered depth image's pixel grid.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "sim/structured_light.h"

namespace mmh::sim::internal {

// SpeckleScene::occluded's bits: which source does not see the pixel.
inline constexpr uint8_t kProjectorShadowBit = 1;
inline constexpr uint8_t kIrCameraBit = 2;

// Per-pixel geometry of the depth view (#width by #height, row-major).
struct SpeckleScene {
  const float* depth = nullptr;          // along the optical axis [m]; +inf where nothing was hit
  const float* disparity = nullptr;      // IR disparity f b / z [px]; 0 where nothing was hit
  const float* cos_incidence = nullptr;  // in [0, 1]
  // Hidden from the projector (kProjectorShadowBit) or the IR camera (kIrCameraBit); 0: seen.
  const uint8_t* occluded = nullptr;
  const float* ir_diffuse = nullptr;     // SurfaceMaterial: ir_albedo (1 - specularity)
  const float* ir_specular = nullptr;    // SurfaceMaterial: specularity
  // SurfaceMaterial::subsurface_mm in metres (nullptr: every surface opaque) and the depth view's
  // focal length [px], which turns it into the dots' blur in pixels at each depth.
  const float* subsurface_m = nullptr;
  float focal_px = 0;
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
  ~SpeckleMatcher();

  // The IR image (#width by #height) in ADC counts (0 .. 2^adc_bits - 1), its sensor noise keyed
  // by `key` (counter-based: the same for any thread count).
  void RenderIr(const SpeckleScene& scene, uint32_t key, uint16_t* ir) const;
  // Depth from the IR image (0 = missing); `cause` (optional, #pixels) says why. Not reentrant
  // (per-frame scratch); the same bytes for any thread count.
  void Match(const SpeckleScene& scene, const uint16_t* ir, const SpeckleOutput& output,
             uint16_t* depth, MissingCause* cause = nullptr);

  // The reference image at integer column x (>= x_min()) of row v in ADC counts, as matched:
  // the pattern at whole pixels, scaled so that its brightest sample is full scale.
  int Reference(int x, int v) const;
  // The pattern at sub-pixel column x of row v, as projected (linear between 1/8 px samples).
  float Pattern(float x, int v) const;
  // The pattern as a translucent surface returns it at sub-pixel column x of row v: the
  // projected pattern around x blurred by a Gaussian of sigma_px (rows beyond the image's
  // repeat its first or last).
  // `weights`: scratch.
  float ScatteredPattern(float x, int v, float sigma_px, std::vector<float>& weights) const;
  // Row v's dots (#width, DotsRow's) where scene.subsurface_m is above 0: ScatteredPattern at
  // each pixel's point of the pattern. `weights`: scratch.
  void ScatterDots(const SpeckleScene& scene, int v, float* dots,
                   std::vector<float>& weights) const;
  int x_min() const { return x_min_; }
  // The integer disparity at which pixel p's search is centred (-1: nothing hit), from the
  // rendered disparity (as Match computes it).
  int SearchCentre(float disparity) const;

 private:
  struct BandScratch;
  // Row v's window statistics and searches into row r of the band's scratch.
  void PrepareRow(int v, int r, BandScratch& s) const;
  // Rows [v0, v1) (their windows inside the image).
  // With first_code (slanted_windows) the verdicts and disparities go there and to
  // first_disparity (#pixels) instead of depth and cause.
  void MatchBand(const SpeckleScene& scene, const SpeckleOutput& output, int v0, int v1,
                 BandScratch& s, uint16_t* depth, MissingCause* cause, int* first_code,
                 float* first_disparity) const;
  // StructuredLightOptions::lattice_search: the matched pixels of row v, columns [start, start +
  // n), moved to the raw lattice value whose reference shift correlates best (a climb from the
  // Gaussian fit's, within a pixel of the integer match).
  // `sum`, `inverse_norm`: the IR windows' statistics of pixels [start, start + n) of row v.
  void SearchLattice(const SpeckleOutput& output, int v, int start, int n, const int* code,
                     const int* best_d, const int32_t* sum, const double* inverse_norm,
                     float* disparity) const;
  // The correlation of pixel (u, v)'s window, whose IR sum and inverse norm are given, with the
  // reference shifted by raw value `raw`.
  double LatticeScore(int u, int v, int raw, int32_t sum, double inverse_norm) const;
  // StructuredLightOptions::slanted_windows: rows [v0, v1)'s matched pixels (frame_code_,
  // frame_disparity_) refined by the plane fitted to the first match's disparities under each
  // window, then turned into depth and cause.
  void RefineSlantedRows(const SpeckleOutput& output, int v0, int v1, uint16_t* depth,
                         MissingCause* cause) const;
  // SlantedWindows::kSheared: pixel (u, v)'s disparity matched again with the window sheared by
  // (g_u, g_v) [px/px], starting from d1; d1 where the window has no contrast.
  double ShearedDisparity(const SpeckleOutput& output, int u, int v, double d1, double g_u,
                          double g_v) const;
  // SlantedWindows::kFirstOrder: centroids_, once per matcher.
  void PrepareCentroids();
  // The correlation of pixel (u, v)'s window (IR sum `sum`, inverse norm given) with the pattern
  // at disparity d sheared by (g_u, g_v) [px/px]: window pixel (i, j) against the pattern at
  // column u + i - d - g_u i - g_v j of row v + j (linear between its 1/8 px samples).
  double SlantedScore(int u, int v, double d, double g_u, double g_v, double sum,
                      double inverse_norm) const;
  // Depth and cause of n pixels from their verdicts and disparities.
  void Output(const SpeckleOutput& output, const int* code, const float* disparity, int n,
              uint16_t* depth, MissingCause* cause) const;

  StructuredLightOptions options_;
  int width_ = 0, height_ = 0;
  int radius_ = 0;       // window_px / 2
  int x_min_ = 0;        // first integer pattern column (negative: disparities shift left)
  int columns_ = 0;      // integer pattern columns
  int max_d_ = 0;        // largest integer disparity matched
  int levels_ = 0;       // 2^adc_bits - 1
  static constexpr int kSubsamples = 8;
  int samples_ = 0;      // pattern samples per row: columns_ * kSubsamples + 1
  std::vector<float> pattern_;      // #height by samples_
  std::vector<int32_t> reference_;  // #height by columns_, ADC counts
  // Per row and integer column of the reference: the window's sum and 1 / sqrt(n sum of squares -
  // sum^2) (0 where that is 0), integer sums exact.
  std::vector<int32_t> reference_sum_;
  std::vector<double> reference_inverse_norm_;
  // Per frame and pixel: SearchCentre (-1: nothing hit), the same with a large number for -1,
  // and why the pixel is not searched (MissingCause: nothing hit, shadow; kValid: it is).
  std::vector<int> centre_, centre_low_, blocked_;
  std::vector<int32_t> units_by_raw_;  // per frame: depth units of raw values 0 .. 2047 (0: none)
  std::vector<int32_t> wide_ir_;        // per frame: the IR image, rows padded to width + 16
  // lattice_search: the pattern at sample positions k + phase (ADC counts, as reference_), so that
  // every raw lattice value's shift is a whole sample; for raw_offset lattice_offset_. Stored by
  // phase k mod 8, then row, then column k div 8 (columns_ per row), so that a window's
  // row is contiguous.
  std::vector<int32_t> lattice_reference_;
  float lattice_offset_ = -1;
  int lattice_floor_ = 0;  // floor(-raw_offset)
  double reference_scale_ = 0;
  // slanted_windows, per frame and pixel: the first match's verdict (MissingCause) and disparity.
  std::vector<int> frame_code_;
  std::vector<float> frame_disparity_;
  // SlantedWindows::kFirstOrder: per row, integer column c of the reference, 1/8 px phase q and
  // axis (u, v), the centroid [1/centroid_units_ px] of (P(x + 1/2) - P(x - 1/2))^2 over the window
  // centred at pattern position c + q/8 (P: the projected pattern of the window's rows); a row's
  // in the order its pixels read them.
  // |centroid| <= window_px / 2 px, so floor(127 / (window_px / 2)) units per px fit a byte (the
  // default window: 31, rounding 1/62 px at most); a frame reads most of the table, and bytes
  // halve that traffic.
  double centroid_units_ = 0;
  std::vector<int8_t> centroids_;
  // Scratch per worker thread (by its index in the task arena), kept from frame to frame.
  std::vector<std::unique_ptr<BandScratch>> scratch_;
};

}  // namespace mmh::sim::internal
