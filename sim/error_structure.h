// The structure of a depth sensor's errors, for comparing real frames with rendered ones
// (`mmh sensor-check`): why pixels are missing, how wide the missing bands beside depth edges
// are, and how depth residuals on planes correlate in space (block matching correlates them over
// its window; per-pixel noise does not).
//
// Missing pixels by cause, from the depth image alone (real frames carry no labels). Each
// horizontal run of missing pixels in a row is classified by its valid neighbours left (z_l) and
// right (z_r):
//  - border: it touches the image's left or right side;
//  - shadow: z_r nearer than z_l by more than step_fraction (the projector sits at +x of the IR
//    camera, so its shadow falls left of near edges);
//  - edge: z_l nearer than z_r by more than step_fraction (the far side of a near edge: the IR
//    camera's occlusion and the correlation window straddling two surfaces);
//  - range: both neighbours beyond far_m (the far end of the sensor's range);
//  - low signal: the rest (dark, shiny, grazing, thin: the pattern did not come back).
// Shadow and edge runs give the band widths (median run length beside a depth step), and the
// widths across the band (BandWidthsAcross: the run along the row and the one along the column
// through each pixel, combined so that a band's slant does not count).
//
// Residual autocorrelation. The image is tiled with patch_size windows; a fully valid window
// seen at no more than max_incidence_deg gets a least-squares plane; windows whose residual sigma
// exceeds outlier_factor times the median of all windows (edges inside) are left out. Pooled
// over windows, rho(k) = sum r(u, v) r(u + k, v) / sum r(u, v)^2 (horizontal and vertical lags
// k = 1 .. patch_size / 2); the correlation length is the lag where rho falls to 1/e (linear
// between lags, starting from rho(0) = 1).
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/image_io.h"
#include "core/rigid3.h"
#include "sim/kinect_model.h"
#include "sim/structured_light.h"

namespace mmh::sim {

struct ErrorStructureOptions {
  double step_fraction = 0.05;  // relative depth step that makes a run a shadow or edge
  double far_m = 3.5;           // both neighbours beyond: range
  int patch_size = 9;           // odd
  double max_incidence_deg = 60.0;
  double outlier_factor = 3.0;
  double min_depth_m = 0.4;  // patches outside [min_depth_m, max_depth_m] are left out
  double max_depth_m = 4.0;

  void Validate(const std::string& prefix) const;
};

struct ErrorStructure {
  // Shares of all pixels.
  double missing_border = 0, missing_shadow = 0, missing_edge = 0, missing_range = 0,
         missing_low_signal = 0;
  double shadow_band_px = 0;  // median length of shadow runs (NaN: none)
  double edge_band_px = 0;    // median length of edge runs (NaN: none)
  // Median over the shadow (edge) pixels of BandWidthsAcross (NaN: none).
  double shadow_band_across_px = 0, edge_band_across_px = 0;
  int patches = 0;
  // Median over patches of residual sigma / sqrt(sigma_z^2 + step^2 / 12) (AxialNoiseModel,
  // LatticeStep): the small-patch noise relative to the per-pixel model.
  double noise_over_model = 0;
  // The same per incidence angle of the patch's plane: [0, 20), [20, 40), [40, 60] deg (NaN: no
  // patch); kIncidenceBins of kIncidenceBinDeg each.
  static constexpr int kIncidenceBins = 3;
  static constexpr double kIncidenceBinDeg = 20.0;
  std::array<double, kIncidenceBins> noise_over_model_by_incidence{};
  std::array<int, kIncidenceBins> patches_by_incidence{};  // the windows in each
  std::vector<double> autocorrelation;  // rho(1) .. rho(patch_size / 2)
  // The same along the rows (horizontal lags, the direction the matcher searches) and along the
  // columns alone: a block matcher's window shape shows in their ratio.
  std::vector<double> autocorrelation_along_rows, autocorrelation_along_columns;
  double correlation_length_px = 0;
};

// The temporal structure: how much of a frame's residuals on planes the next frames of the same
// view keep. A real block matcher's errors come from the speckle pattern on the surface, fixed
// while neither moves, and from the IR image's noise, new in every frame; the per-pixel model's
// are new in every frame.
struct TemporalCorrelation {
  // sum r_a r_b / sqrt(sum r_a^2 sum r_b^2) over the pixels of the windows kept in both frames
  // (AnalyseErrorStructure's planar windows without outliers; NaN: none).
  double rho = 0;
  int patches = 0;
};

// depth_m: width x height row-major [m], 0 = missing; intrinsics for incidence angles.
ErrorStructure AnalyseErrorStructure(const std::vector<float>& depth_m, int width, int height,
                                     const PinholeIntrinsics& intrinsics,
                                     const KinectCalibration& calibration,
                                     const AxialNoiseModel& noise,
                                     const ErrorStructureOptions& options = {});

nlohmann::json ToJson(const ErrorStructure& structure);

// Two frames of one view (the same camera pose; a static scene, or its static part: windows on
// moving objects are rarely planar in both at the same place).
TemporalCorrelation AnalyseTemporalCorrelation(const std::vector<float>& a_m,
                                               const std::vector<float>& b_m, int width,
                                               int height, const PinholeIntrinsics& intrinsics,
                                               const ErrorStructureOptions& options = {});

// Frame b's depth along the surface frame a sees: each pixel of a with a depth, carried by the
// camera's motion b_T_a (frame a's camera to frame b's) into b's image, takes the depth b
// measured at the nearest pixel there; 0 where either misses or the point leaves b's image.
// AnalyseTemporalCorrelation(a, SurfaceAlignedDepth(...)) then correlates the residuals at the
// same points of the surface rather than at the same pixels: a block matcher's errors from the
// projected pattern stay with the pixel (the projector moves with the camera), errors from the
// surface itself (its texture in the IR, laser speckle) move with the surface. Both frames share
// `intrinsics`.
std::vector<float> SurfaceAlignedDepth(const std::vector<float>& a_m, const std::vector<float>& b_m,
                                       int width, int height, const PinholeIntrinsics& intrinsics,
                                       const Rigid3& b_T_a);

// Why a pixel is missing, judged from the depth image alone (real frames carry no labels): runs of
// missing pixels along a row touching the image's side (border), with the far side on their left
// (shadow: the projector sits to the right) or on their right (edge), between neighbours beyond
// far_m (range), otherwise low signal. Run lengths of shadow and edge runs appended when given.
enum class MissingClass : uint8_t { kValid = 0, kBorder, kShadow, kEdge, kRange, kLowSignal };
std::vector<MissingClass> ClassifyMissing(const std::vector<float>& depth_m, int width, int height,
                                          const ErrorStructureOptions& options = {},
                                          std::vector<double>* shadow_runs = nullptr,
                                          std::vector<double>* edge_runs = nullptr);

// The width across the missing band through each pixel, whatever the band's slant: a straight
// band of width w at angle t to the rows has runs r = w / |sin t| along the row and
// c = w / |cos t| along the column, and 1 / r^2 + 1 / c^2 = 1 / w^2, so
// w = (r^-2 + c^-2)^(-1/2) (a vertical band: r; a horizontal one: c; a slant of 45 deg: r / sqrt 2).
// Run lengths r and c count the missing pixels (any cause) in a row and in a column; the image's
// sides end a run. Returns width x height values, 0 at valid pixels.
std::vector<float> BandWidthsAcross(const std::vector<float>& depth_m, int width, int height);

// Missing pixels around one object (issue 23's "comparable table-top scene": a real frame and
// the same view rendered, the same object seen from the same place). The neighbourhood is the
// object's mask (width x height, non-zero = object) grown by `radius_px` pixels (a square,
// Chebyshev distance); missing_share is the share of its pixels that are missing, and the band
// widths are the medians of the ClassifyMissing shadow and edge runs with a pixel in it. Lengths
// and radius are in this frame's pixels; compare frames of different focal lengths at radii in
// the same proportion and with the bands scaled by that proportion.
struct NeighbourhoodStructure {
  double pixels = 0;         // in the neighbourhood
  double missing_share = 0;  // of them
  double shadow_band_px = 0, edge_band_px = 0;  // NaN: no run
  // Median over those runs' pixels of BandWidthsAcross (NaN: no run).
  double shadow_band_across_px = 0, edge_band_across_px = 0;
  int shadow_runs = 0, edge_runs = 0;
  // The object's silhouette (sim/silhouette_bleed.h), where the mask is an object's (NaN
  // otherwise): the mean bleed and erosion at its shadow-side and edge-side ends.
  double shadow_side_bleed_px = std::numeric_limits<double>::quiet_NaN();
  double edge_side_bleed_px = std::numeric_limits<double>::quiet_NaN();
  double shadow_side_erosion_px = std::numeric_limits<double>::quiet_NaN();
  double edge_side_erosion_px = std::numeric_limits<double>::quiet_NaN();
  int shadow_side_ends = 0, edge_side_ends = 0;  // the silhouette's ends measured
  // The object's interior (MissingInside: its mask shrunk by the caller's radius), where the mask
  // is an object's: its pixels and the share of them missing (NaN otherwise), the holes on the
  // surface itself, clear of the bands at its outline.
  double interior_pixels = 0;
  double interior_missing_share = std::numeric_limits<double>::quiet_NaN();
};
// `excluded` (empty, or width x height, non-zero = left out): pixels taken out of the
// neighbourhood, and runs with a pixel there not counted: the parts of a real frame near objects
// the rendered view does not hold.
NeighbourhoodStructure AnalyseNeighbourhood(const std::vector<float>& depth_m, int width,
                                            int height, std::span<const uint8_t> mask,
                                            int radius_px,
                                            const ErrorStructureOptions& options = {},
                                            std::span<const uint8_t> excluded = {});

// The mask (width x height, non-zero = in) grown by radius_px pixels: a square of side
// 2 radius_px + 1 around each pixel in it (Chebyshev distance). Returns 0 / 1 per pixel.
std::vector<uint8_t> GrowMask(std::span<const uint8_t> mask, int width, int height, int radius_px);

// The mask's interior: the pixels whose whole square of side 2 radius_px + 1 lies in the mask
// (and in the image), `excluded` (empty, or non-zero = left out) taken out; sets
// interior_pixels and interior_missing_share of `n` (NaN: no interior pixel).
void MissingInside(const std::vector<float>& depth_m, int width, int height,
                   std::span<const uint8_t> mask, int radius_px, std::span<const uint8_t> excluded,
                   NeighbourhoodStructure& n);

// The classes against a rendered frame's exact causes (KinectSensor::missing_causes), in % of all
// pixels: how well the depth-image rules that classify real frames name the sensor's causes.
std::string FormatCauseTable(const std::vector<MissingClass>& classes,
                             std::span<const MissingCause> causes);

// Real against rendered: one row per statistic, a column per named structure, then the ratio of
// each rendered column (indices `rendered`) to the real one (index `reference`), and the goal
// (within 20 % of the real frame's).
std::string FormatRealismTable(const std::vector<std::string>& names,
                               const std::vector<ErrorStructure>& structures, size_t reference,
                               const std::vector<size_t>& rendered);

// A depth image seen through other intrinsics from the same place: each pixel of `to` takes
// the `from` pixel nearest its ray (u_from = cx_from + fx_from (u - cx_to) / fx_to, rounded;
// rows alike), 0 where that lies outside `from`; lens distortion is not modelled. For looking at
// frames of different focal lengths side by side at the same scale.
std::vector<float> ResampleDepthNearest(const std::vector<float>& depth_m,
                                        const PinholeIntrinsics& from,
                                        const PinholeIntrinsics& to);

// Depth images side by side as one RGB image for a human to compare (grey by inverse depth
// over [0.5, 4] m, near bright; missing pixels red); every image width x height.
RgbImage DepthSideBySide(const std::vector<const std::vector<float>*>& depths_m, int width,
                         int height);

}  // namespace mmh::sim
