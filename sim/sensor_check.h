// Statistics of one depth frame that compare a sensor with the Kinect v1 model
// (sim/kinect_model.h): missing pixels, the depth-step law of the disparity lattice, and the
// axial noise on small planar patches. `mmh sensor-check` prints them for real frames (TUM, NYU,
// SUN RGB-D) beside rendered ones.
//
// Depth-step law. A Kinect v1 reports depths on the lattice z_n = C / (raw_offset - n), C = s f b,
// so two adjacent lattice depths z_a < z_b satisfy exactly
//     z_b - z_a = z_a z_b / C,        i.e.  k_i = (z_b - z_a) / (z_a z_b) = 1 / C = k,
// which is the law dz = k z^2 with k = 1 / (s f b) (LatticeStep). The estimator:
//  1. takes the distinct depth values of the frame in [min_depth_m, max_depth_m], sorted, and the
//     pairs of adjacent ones; pairs closer than min_step_quanta storage quanta are dropped (the
//     file's rounding, e.g. TUM's 1 mm or SUN's 1 mm, would dominate their step);
//  2. where the frame is sparse, adjacent distinct values skip lattice points and k_i is a
//     multiple m k; so the pairs are binned by depth and the fundamental k0 is the smallest
//     per-bin median k_i among bins with at least min_pairs_per_bin pairs (a dense bin's median
//     is one lattice step);
//  3. each pair's multiple is m_i = round(k_i / k0) (pairs with m_i > max_step_multiple, wide
//     gaps, are left out) and k = median(k_i / m_i), the "smallest common step".
// For NYU's raw frames the raw integers themselves are the lattice: their adjacent distinct values
// differ by exactly 1 (reported as RawDisparityStatistics), and z = 351.3 / (1092.5 - raw) gives
// k = 1 / 351.3.
//
// Noise. The image is tiled with patch_size x patch_size windows; a window with every pixel valid
// gets a least-squares plane z = a u + b v + c, residual sigma = sqrt(SSR / (n - 3)), and the
// incidence angle of its plane (from the intrinsics); windows steeper than max_incidence_deg are
// left out. Per depth bin the median residual is compared with the model's sigma_z(z, theta)
// (AxialNoiseModel::Sigma) and with sqrt(sigma_z^2 + dz^2 / 12), which adds the lattice
// quantisation (a uniform step dz contributes dz^2 / 12 when the noise dithers across steps; a
// patch on one lattice value shows less). Depth edges inside a window inflate its residual; the
// median per bin is robust to the few such windows.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/camera.h"
#include "sim/kinect_model.h"

namespace mmh::sim {

// NYU Depth V2 raw calibration: z [m] = 351.3 / (1092.5 - raw).
inline constexpr double kNyuDepthNumerator = 351.3;  // [m raw units]
inline constexpr double kNyuRawOffset = 1092.5;
// NYU Depth V2's depth (IR) camera, whose image the raw frames are (the toolbox's camera_params.m).
inline constexpr PinholeIntrinsics kNyuDepthIntrinsics{
    640, 480, 582.62448167737955, 582.69103270988637, 313.04475870804731, 238.44389626620386};

struct SensorCheckOptions {
  // Width of the depth bins of the tables [m].
  double bin_width_m = 0.25;
  // Depths outside [min_depth_m, max_depth_m] are ignored by the step law and the noise [m]
  // (Kinect v1 range 0.5-4 m, DESIGN.md; real frames carry coarse readings out to ~10 m).
  double min_depth_m = 0.4;
  double max_depth_m = 10.0;
  // Storage quantum of the depth values [m]: 0 = estimate it (the largest of 10, 5, 2, 1, 0.5,
  // 0.2, 0.1 mm of which 95 % of the distinct values are whole multiples; none: 0).
  double depth_quantum_m = 0.0;
  // Adjacent distinct values closer than this many quanta are not used for the step law.
  double min_step_quanta = 4.0;
  // A depth bin needs this many pairs to set the fundamental step.
  int min_pairs_per_bin = 5;
  // Pairs more than this many lattice steps apart are left out of the fit.
  int max_step_multiple = 4;
  // Side of the noise windows [px], odd.
  int patch_size = 9;
  // Windows whose plane is seen more obliquely than this are left out of the noise [deg]
  // (Nguyen et al. 2012: the axial model holds for 10-60 degrees).
  double max_incidence_deg = 60.0;
  // Intrinsics of the depth image, for incidence angles (default: ROS Kinect v1).
  PinholeIntrinsics intrinsics;
  // The model to compare with.
  KinectCalibration calibration;
  AxialNoiseModel noise;
  // Lattice constant of the raw disparity, for RawDisparityStatistics [m raw units] (NYU).
  double raw_lattice_constant = kNyuDepthNumerator;

  template <class V>
  void VisitFields(V& v) {
    v("bin_width_m", bin_width_m);
    v("min_depth_m", min_depth_m);
    v("max_depth_m", max_depth_m);
    v("depth_quantum_m", depth_quantum_m);
    v("min_step_quanta", min_step_quanta);
    v("min_pairs_per_bin", min_pairs_per_bin);
    v("max_step_multiple", max_step_multiple);
    v("patch_size", patch_size);
    v("max_incidence_deg", max_incidence_deg);
    v("intrinsics", intrinsics);
    v("calibration", calibration);
    v("noise", noise);
    v("raw_lattice_constant", raw_lattice_constant);
  }
  void Validate(const std::string& prefix) const;
};

// The fitted pairs (at most max_step_multiple steps apart) whose midpoints fall in one bin.
struct DepthStepBin {
  double z_min_m = 0;  // bin [z_min, z_max) of the pair midpoints [m]
  double z_max_m = 0;
  int pairs = 0;
  double median_z_m = 0;            // median pair midpoint [m]
  double median_step_m = 0;         // median z_b - z_a [m]
  double median_k = 0;              // median (z_b - z_a) / (z_a z_b) [1/m]
  double fundamental_fraction = 0;  // share of pairs one lattice step apart
  double model_step_m = 0;          // LatticeStep at median_z_m [m]
};

struct DepthStepLaw {
  double depth_quantum_m = 0;  // storage quantum used (given or estimated) [m]
  int distinct_values = 0;     // in the depth range
  int pairs = 0;               // usable pairs
  int pairs_fitted = 0;        // of which within max_step_multiple steps (the rest: gaps)
  double fundamental_k = 0;    // k0 of step 2 [1/m]
  double k = 0;                // fitted k of dz = k z^2 [1/m]; NaN without pairs
  double fundamental_fraction = 0;
  double model_k = 0;  // 1 / (s f b) [1/m]
  std::vector<DepthStepBin> bins;
  std::vector<std::string> warnings;
};

struct NoiseBin {
  double z_min_m = 0;
  double z_max_m = 0;
  int patches = 0;
  double median_residual_m = 0;     // median plane-fit residual sigma [m]
  double median_incidence_deg = 0;  // median incidence angle of the patches [deg]
  double model_sigma_m = 0;         // median AxialNoiseModel::Sigma(z, theta) [m]
  double model_quantisation_m = 0;  // median LatticeStep(z) / sqrt(12) [m]
  double model_total_m = 0;         // median sqrt(sigma^2 + step^2 / 12) [m]
};

struct RawDisparityStatistics {
  bool present = false;
  int valid_pixels = 0;
  int distinct_values = 0;
  int min_raw = 0;
  int max_raw = 0;
  double unit_step_fraction = 0;  // adjacent distinct raw values exactly 1 apart
  double median_step = 0;         // [raw units]
  double implied_k = 0;           // median_step / raw_lattice_constant [1/m]
};

struct SensorStatistics {
  std::string name;
  int width = 0;
  int height = 0;
  int valid_pixels = 0;
  double missing_fraction = 0;
  double depth_min_m = 0;
  double depth_median_m = 0;
  double depth_max_m = 0;
  DepthStepLaw step_law;
  int noise_patches = 0;
  std::vector<NoiseBin> noise_bins;
  RawDisparityStatistics raw;
};

// Share of pixels that are missing (0, negative or not finite); 0 for an empty image.
double MissingFraction(const std::vector<float>& depth_m);

// The step law of the frame's distinct depth values (see the file comment).
DepthStepLaw FitDepthStepLaw(const std::vector<float>& depth_m, const SensorCheckOptions& options);

// Plane-fit residuals of the fully valid windows, per depth bin (see the file comment).
std::vector<NoiseBin> EstimatePatchNoise(const std::vector<float>& depth_m, int width, int height,
                                         const SensorCheckOptions& options, int* patches = nullptr);

// Distinct raw values and their steps (2047 = invalid is left out).
RawDisparityStatistics AnalyseRawDisparity(const std::vector<uint16_t>& raw,
                                           const SensorCheckOptions& options);

// All of the above. depth_m: width x height row-major [m], 0 = missing; raw: the same frame's raw
// disparity when known (NYU), else nullptr. InputError for a size mismatch or invalid options.
SensorStatistics ComputeSensorStatistics(const std::string& name, const std::vector<float>& depth_m,
                                         int width, int height,
                                         const SensorCheckOptions& options = {},
                                         const std::vector<uint16_t>* raw = nullptr);

// Conversions of the stored depth images to metres (0 stays 0 = missing).
std::vector<float> DepthMetresFromUnits(const std::vector<uint16_t>& values,
                                        double metres_per_unit);
// NYU raw: z = 351.3 / (1092.5 - raw); 2047 and raw >= 1092 (no finite depth) give 0.
std::vector<float> DepthMetresFromNyuRaw(const std::vector<uint16_t>& raw);

nlohmann::json ToJson(const SensorStatistics& statistics);

// A plain-text table, one column per SensorStatistics (its name as the header), rows for the
// missing share, depth range, step law (measured, with the model in parentheses), per-bin steps
// and noise. Bins are aligned by depth range across columns; '-' where a column has none.
std::string FormatSensorTable(const std::vector<SensorStatistics>& columns);

}  // namespace mmh::sim
