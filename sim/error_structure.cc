#include "sim/error_structure.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>

#include "core/error.h"
#include "sim/internal/depth_sample.h"

namespace mmh::sim {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using internal::Median;
using internal::ValidDepth;

// A fully valid patch_size window of a depth image with its least-squares plane
// z = a u + b v + c: where it lies, its residuals, their sigma, the per-pixel model's sigma there
// (when asked) and the plane's incidence.
struct Patch {
  int u0 = 0, v0 = 0;
  Eigen::VectorXd residual;
  double sigma = 0, model = 0, incidence_deg = 0;
};

// The patches of the image tiled by windows of patch_size, fully valid within [min_depth_m,
// max_depth_m] and seen at no more than max_incidence_deg. `calibration` and `noise` give
// Patch::model (left 0 without them).
std::vector<Patch> PlanarPatches(const std::vector<float>& depth_m, int width, int height,
                                 const PinholeIntrinsics& intrinsics,
                                 const ErrorStructureOptions& options,
                                 const KinectCalibration* calibration,
                                 const AxialNoiseModel* noise) {
  const int n = options.patch_size;
  const double max_tan = std::tan(options.max_incidence_deg * std::numbers::pi / 180.0);
  Eigen::MatrixXd design(n * n, 3);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) design.row(j * n + i) << i - n / 2, j - n / 2, 1.0;
  }
  const Eigen::MatrixXd solve = (design.transpose() * design).inverse() * design.transpose();
  std::vector<Patch> patches;
  for (int v0 = 0; v0 + n <= height; v0 += n) {
    for (int u0 = 0; u0 + n <= width; u0 += n) {
      Eigen::VectorXd z(n * n);
      bool full = true;
      for (int j = 0; j < n && full; ++j) {
        for (int i = 0; i < n; ++i) {
          const float d = depth_m[static_cast<size_t>(v0 + j) * width + u0 + i];
          if (!ValidDepth(d) || d < options.min_depth_m || d > options.max_depth_m) {
            full = false;
            break;
          }
          z[j * n + i] = d;
        }
      }
      if (!full) continue;
      const Eigen::Vector3d plane = solve * z;
      const double zc = plane[2];
      // Incidence: the plane's normal in the camera frame from its depth gradient (per pixel,
      // dz/du = a, dz/dv = b; a pixel spans z / f metres).
      const double gx = plane[0] * intrinsics.fx / zc, gy = plane[1] * intrinsics.fy / zc;
      if (std::hypot(gx, gy) > max_tan) continue;
      Patch p;
      p.u0 = u0;
      p.v0 = v0;
      p.residual = z - design * plane;
      p.sigma = std::sqrt(p.residual.squaredNorm() / (n * n - 3));
      const double theta = std::atan(std::hypot(gx, gy));
      if (calibration != nullptr && noise != nullptr) {
        const double step = LatticeStep(zc, *calibration);
        const double sigma_z = noise->Sigma(zc, theta);
        p.model = std::sqrt(sigma_z * sigma_z + step * step / 12.0);
      }
      p.incidence_deg = theta * 180.0 / std::numbers::pi;
      patches.push_back(std::move(p));
    }
  }
  return patches;
}

// The patches whose residual sigma is at most outlier_factor times the median of all (windows
// with an edge or a fold inside are left out).
std::vector<const Patch*> InlierPatches(const std::vector<Patch>& patches,
                                        const ErrorStructureOptions& options) {
  std::vector<double> sigmas;
  for (const Patch& p : patches) sigmas.push_back(p.sigma);
  const double typical = Median(sigmas);
  std::vector<const Patch*> inliers;
  for (const Patch& p : patches) {
    if (p.sigma <= options.outlier_factor * typical) inliers.push_back(&p);
  }
  return inliers;
}

void CheckDepthSize(const std::vector<float>& depth_m, int width, int height) {
  if (width < 1 || height < 1 || depth_m.size() != static_cast<size_t>(width) * height) {
    ThrowBadValue("depth", std::to_string(depth_m.size()) + " pixels",
                  std::to_string(width) + "x" + std::to_string(height) + " pixels");
  }
}

}  // namespace

void ErrorStructureOptions::Validate(const std::string& prefix) const {
  if (!(step_fraction > 0 && step_fraction < 1)) {
    ThrowBadValue(prefix + ".step_fraction", FormatNumber(step_fraction), "a fraction in (0, 1)");
  }
  RequirePositive(far_m, prefix + ".far_m", "m");
  if (patch_size < 5 || patch_size % 2 == 0 || patch_size > 63) {
    ThrowBadValue(prefix + ".patch_size", std::to_string(patch_size), "an odd size in [5, 63] px");
  }
  if (!(max_incidence_deg > 0 && max_incidence_deg < 90)) {
    ThrowBadValue(prefix + ".max_incidence_deg", FormatNumber(max_incidence_deg),
                  "an angle in (0, 90) degrees");
  }
  RequirePositive(outlier_factor, prefix + ".outlier_factor");
  if (!(min_depth_m >= 0 && max_depth_m > min_depth_m)) {
    ThrowBadValue(prefix + ".max_depth_m", FormatNumber(max_depth_m),
                  "a depth above min_depth_m (" + FormatNumber(min_depth_m) + " m)");
  }
}

// Calls run(first, end) for each maximal stretch [first, end) of missing pixels along one line of
// an image: the n pixels depth_m[start + k step], k = 0 .. n - 1 (a row: step 1; a column: step
// width).
template <class Run>
void ForEachMissingRun(const std::vector<float>& depth_m, size_t start, size_t step, int n,
                       Run run) {
  for (int k = 0; k < n;) {
    if (ValidDepth(depth_m[start + k * step])) {
      ++k;
      continue;
    }
    const int first = k;
    while (k < n && !ValidDepth(depth_m[start + k * step])) ++k;
    run(first, k);
  }
}

std::vector<MissingClass> ClassifyMissing(const std::vector<float>& depth_m, int width, int height,
                                          const ErrorStructureOptions& options,
                                          std::vector<double>* shadow_runs,
                                          std::vector<double>* edge_runs) {
  std::vector<MissingClass> classes(depth_m.size(), MissingClass::kValid);
  for (int v = 0; v < height; ++v) {
    const size_t row = static_cast<size_t>(v) * width;
    ForEachMissingRun(depth_m, row, 1, width, [&](int first, int u) {
      const double length = u - first;
      MissingClass c;
      if (first == 0 || u == width) {
        c = MissingClass::kBorder;
      } else {
        const double left = depth_m[row + first - 1], right = depth_m[row + u];
        const double nearer = std::min(left, right);
        if (left - right > options.step_fraction * nearer) {
          c = MissingClass::kShadow;
          if (shadow_runs != nullptr) shadow_runs->push_back(length);
        } else if (right - left > options.step_fraction * nearer) {
          c = MissingClass::kEdge;
          if (edge_runs != nullptr) edge_runs->push_back(length);
        } else if (nearer > options.far_m) {
          c = MissingClass::kRange;
        } else {
          c = MissingClass::kLowSignal;
        }
      }
      std::fill(classes.begin() + row + first, classes.begin() + row + u, c);
    });
  }
  return classes;
}

std::vector<float> BandWidthsAcross(const std::vector<float>& depth_m, int width, int height) {
  CheckDepthSize(depth_m, width, height);
  const size_t pixels = static_cast<size_t>(width) * height;
  std::vector<float> along_row(pixels, 0.0f), across(pixels, 0.0f);
  for (int v = 0; v < height; ++v) {
    const size_t row = static_cast<size_t>(v) * width;
    ForEachMissingRun(depth_m, row, 1, width, [&](int first, int end) {
      std::fill(along_row.begin() + row + first, along_row.begin() + row + end,
                static_cast<float>(end - first));
    });
  }
  for (int u = 0; u < width; ++u) {
    ForEachMissingRun(depth_m, u, width, height, [&](int first, int end) {
      const double c = end - first;
      for (int k = first; k < end; ++k) {
        const size_t p = static_cast<size_t>(k) * width + u;
        const double r = along_row[p];
        across[p] = static_cast<float>(1.0 / std::sqrt(1.0 / (r * r) + 1.0 / (c * c)));
      }
    });
  }
  return across;
}

std::vector<uint8_t> GrowMask(std::span<const uint8_t> mask, int width, int height,
                              int radius_px) {
  const size_t pixels = static_cast<size_t>(width) * height;
  if (mask.size() != pixels) {
    ThrowBadValue("mask", std::to_string(mask.size()) + " pixels", std::to_string(pixels));
  }
  if (radius_px < 0) ThrowBadValue("radius_px", std::to_string(radius_px), "0 or more");
  // Along rows, then along columns.
  std::vector<uint8_t> rows(pixels, 0), region(pixels, 0);
  for (int v = 0; v < height; ++v) {
    int last = std::numeric_limits<int>::min() / 2;  // the last mask pixel at or left of u
    for (int u = 0; u < width + radius_px; ++u) {
      if (u < width && mask[static_cast<size_t>(v) * width + u] != 0) last = u;
      const int target = u - radius_px;
      if (target >= 0 && u - last <= 2 * radius_px) rows[static_cast<size_t>(v) * width + target] = 1;
    }
  }
  for (int u = 0; u < width; ++u) {
    int last = std::numeric_limits<int>::min() / 2;
    for (int v = 0; v < height + radius_px; ++v) {
      if (v < height && rows[static_cast<size_t>(v) * width + u] != 0) last = v;
      const int target = v - radius_px;
      if (target >= 0 && v - last <= 2 * radius_px) region[static_cast<size_t>(target) * width + u] = 1;
    }
  }
  return region;
}

namespace {

// The depths, the mask and `excluded` (empty: none) of one width x height image; returns the
// pixel count.
size_t CheckMaskSizes(const std::vector<float>& depth_m, int width, int height,
                      std::span<const uint8_t> mask, std::span<const uint8_t> excluded) {
  const size_t pixels = static_cast<size_t>(width) * height;
  if (depth_m.size() != pixels || mask.size() != pixels ||
      (!excluded.empty() && excluded.size() != pixels)) {
    ThrowBadValue("mask",
                  std::to_string(mask.size()) + " pixels, " + std::to_string(excluded.size()) +
                      " excluded and " + std::to_string(depth_m.size()) + " depths",
                  std::to_string(pixels) + " of each (none excluded: 0)");
  }
  return pixels;
}

}  // namespace

void MissingInside(const std::vector<float>& depth_m, int width, int height,
                   std::span<const uint8_t> mask, int radius_px, std::span<const uint8_t> excluded,
                   NeighbourhoodStructure& n) {
  CheckMaskSizes(depth_m, width, height, mask, excluded);
  // Shrinking the mask is growing its complement; beyond the image counts as outside, so a pixel
  // within radius_px of the image's side is not interior.
  const int pad = radius_px;
  const int padded_width = width + 2 * pad, padded_height = height + 2 * pad;
  std::vector<uint8_t> outside(static_cast<size_t>(padded_width) * padded_height, 1);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      outside[static_cast<size_t>(v + pad) * padded_width + u + pad] =
          mask[static_cast<size_t>(v) * width + u] == 0;
    }
  }
  const std::vector<uint8_t> near_outside =
      GrowMask(outside, padded_width, padded_height, radius_px);
  double inside = 0, missing = 0;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const size_t p = static_cast<size_t>(v) * width + u;
      if (near_outside[static_cast<size_t>(v + pad) * padded_width + u + pad] != 0) continue;
      if (!excluded.empty() && excluded[p] != 0) continue;
      inside += 1;
      if (!ValidDepth(depth_m[p])) missing += 1;
    }
  }
  n.interior_pixels = inside;
  n.interior_missing_share = inside > 0 ? missing / inside : kNaN;
}

NeighbourhoodStructure AnalyseNeighbourhood(const std::vector<float>& depth_m, int width,
                                            int height, std::span<const uint8_t> mask,
                                            int radius_px, const ErrorStructureOptions& options,
                                            std::span<const uint8_t> excluded) {
  const size_t pixels = CheckMaskSizes(depth_m, width, height, mask, excluded);
  std::vector<uint8_t> region = GrowMask(mask, width, height, radius_px);
  auto is_excluded = [&](size_t p) { return !excluded.empty() && excluded[p] != 0; };
  for (size_t p = 0; p < pixels; ++p) {
    if (is_excluded(p)) region[p] = 0;
  }
  NeighbourhoodStructure n;
  double missing = 0;
  for (size_t p = 0; p < pixels; ++p) {
    if (region[p] == 0) continue;
    n.pixels += 1;
    if (!ValidDepth(depth_m[p])) missing += 1;
  }
  n.missing_share = n.pixels > 0 ? missing / n.pixels : kNaN;
  // ClassifyMissing gives every pixel of a run its run's class, and runs are separated by valid
  // pixels, so a run is a maximal stretch of one missing class.
  const std::vector<MissingClass> classes = ClassifyMissing(depth_m, width, height, options);
  const std::vector<float> across = BandWidthsAcross(depth_m, width, height);
  std::vector<double> shadow_runs, edge_runs, shadow_across, edge_across;
  for (int v = 0; v < height; ++v) {
    const size_t row = static_cast<size_t>(v) * width;
    for (int u = 0; u < width;) {
      const MissingClass c = classes[row + u];
      const int first = u;
      bool touches = false, left_out = false;
      while (u < width && classes[row + u] == c) {
        left_out |= is_excluded(row + u);
        touches |= region[row + u++] != 0;
      }
      if (!touches || left_out) continue;
      if (c != MissingClass::kShadow && c != MissingClass::kEdge) continue;
      (c == MissingClass::kShadow ? shadow_runs : edge_runs).push_back(u - first);
      std::vector<double>& widths = c == MissingClass::kShadow ? shadow_across : edge_across;
      widths.insert(widths.end(), across.begin() + row + first, across.begin() + row + u);
    }
  }
  n.shadow_runs = static_cast<int>(shadow_runs.size());
  n.edge_runs = static_cast<int>(edge_runs.size());
  n.shadow_band_px = Median(shadow_runs);
  n.edge_band_px = Median(edge_runs);
  n.shadow_band_across_px = Median(shadow_across);
  n.edge_band_across_px = Median(edge_across);
  return n;
}

std::string FormatCauseTable(const std::vector<MissingClass>& classes,
                             std::span<const MissingCause> causes) {
  constexpr const char* kClassNames[] = {"valid", "border", "shadow",
                                         "edge",  "range",  "low signal"};
  constexpr const char* kCauseNames[] = {"valid",      "border",   "nothing hit", "shadow",
                                         "low signal", "no match", "ambiguous",   "range"};
  constexpr int kClasses = 6, kCauses = 8;
  if (classes.size() != causes.size()) {
    ThrowBadValue("causes", std::to_string(causes.size()) + " pixels",
                  std::to_string(classes.size()) + " pixels");
  }
  std::vector<double> count(kClasses * kCauses, 0.0);
  for (size_t p = 0; p < classes.size(); ++p) {
    count[static_cast<int>(classes[p]) * kCauses + static_cast<int>(causes[p])] += 1;
  }
  const double pixels = static_cast<double>(classes.size());
  std::string text =
      "missing [% of pixels]: from the depth image (rows) against the sensor's own "
      "cause (columns)\n";
  char cell[64];
  std::snprintf(cell, sizeof(cell), "%-12s", "");
  text += cell;
  for (int c = 1; c < kCauses; ++c) {
    std::snprintf(cell, sizeof(cell), "%12s", kCauseNames[c]);
    text += cell;
  }
  text += "\n";
  for (int k = 0; k < kClasses; ++k) {
    std::snprintf(cell, sizeof(cell), "%-12s", kClassNames[k]);
    text += cell;
    for (int c = 1; c < kCauses; ++c) {
      std::snprintf(cell, sizeof(cell), "%12.2f", 100 * count[k * kCauses + c] / pixels);
      text += cell;
    }
    text += "\n";
  }
  return text;
}

ErrorStructure AnalyseErrorStructure(const std::vector<float>& depth_m, int width, int height,
                                     const PinholeIntrinsics& intrinsics,
                                     const KinectCalibration& calibration,
                                     const AxialNoiseModel& noise,
                                     const ErrorStructureOptions& options) {
  options.Validate("error_structure");
  CheckDepthSize(depth_m, width, height);
  ErrorStructure s;
  const double pixels = static_cast<double>(width) * height;
  std::vector<double> shadow_runs, edge_runs;
  const std::vector<MissingClass> classes =
      ClassifyMissing(depth_m, width, height, options, &shadow_runs, &edge_runs);
  std::array<double, 6> count{};  // per MissingClass
  for (const MissingClass c : classes) count[static_cast<int>(c)] += 1;
  s.missing_border = count[static_cast<int>(MissingClass::kBorder)] / pixels;
  s.missing_shadow = count[static_cast<int>(MissingClass::kShadow)] / pixels;
  s.missing_edge = count[static_cast<int>(MissingClass::kEdge)] / pixels;
  s.missing_range = count[static_cast<int>(MissingClass::kRange)] / pixels;
  s.missing_low_signal = count[static_cast<int>(MissingClass::kLowSignal)] / pixels;
  s.shadow_band_px = Median(shadow_runs);
  s.edge_band_px = Median(edge_runs);
  const std::vector<float> across = BandWidthsAcross(depth_m, width, height);
  std::vector<double> shadow_across, edge_across;
  for (size_t p = 0; p < classes.size(); ++p) {
    if (classes[p] == MissingClass::kShadow) shadow_across.push_back(across[p]);
    if (classes[p] == MissingClass::kEdge) edge_across.push_back(across[p]);
  }
  s.shadow_band_across_px = Median(shadow_across);
  s.edge_band_across_px = Median(edge_across);

  const int n = options.patch_size;
  const int lags = n / 2;
  const std::vector<Patch> patches =
      PlanarPatches(depth_m, width, height, intrinsics, options, &calibration, &noise);
  // numerator pools both directions in the order it always has (its value bit for bit); the
  // split sums are the same products by direction.
  std::vector<double> numerator(lags + 1, 0.0), along_rows(lags + 1, 0.0),
      along_columns(lags + 1, 0.0), ratios;
  std::array<std::vector<double>, ErrorStructure::kIncidenceBins> ratios_by_incidence;
  double energy = 0;
  for (const Patch* inlier : InlierPatches(patches, options)) {
    const Patch& p = *inlier;
    ++s.patches;
    ratios.push_back(p.sigma / p.model);
    const int bin = std::min(ErrorStructure::kIncidenceBins - 1,
                             static_cast<int>(p.incidence_deg / ErrorStructure::kIncidenceBinDeg));
    ratios_by_incidence[bin].push_back(p.sigma / p.model);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const double r = p.residual[j * n + i];
        energy += 2 * r * r;
        for (int k = 1; k <= lags; ++k) {
          if (i + k < n) {
            const double product = r * p.residual[j * n + i + k];
            numerator[k] += product;
            along_rows[k] += product;
          }
          if (j + k < n) {
            const double product = r * p.residual[(j + k) * n + i];
            numerator[k] += product;
            along_columns[k] += product;
          }
        }
      }
    }
  }
  s.noise_over_model = Median(ratios);
  for (int b = 0; b < ErrorStructure::kIncidenceBins; ++b) {
    s.noise_over_model_by_incidence[b] = Median(ratios_by_incidence[b]);
    s.patches_by_incidence[b] = static_cast<int>(ratios_by_incidence[b].size());
  }
  s.autocorrelation.assign(lags, kNaN);
  s.autocorrelation_along_rows.assign(lags, kNaN);
  s.autocorrelation_along_columns.assign(lags, kNaN);
  if (energy > 0) {
    for (int k = 1; k <= lags; ++k) {
      // Pairs at lag k are fewer than squares: normalise per pair count (n - k of n per line).
      s.autocorrelation[k - 1] = numerator[k] / energy * n / (n - k);
      s.autocorrelation_along_rows[k - 1] = along_rows[k] / (energy / 2) * n / (n - k);
      s.autocorrelation_along_columns[k - 1] = along_columns[k] / (energy / 2) * n / (n - k);
    }
  }
  const double target = std::exp(-1.0);
  s.correlation_length_px = kNaN;
  if (!s.autocorrelation.empty() && std::isfinite(s.autocorrelation[0])) {
    double previous = 1.0;
    s.correlation_length_px = lags;  // not reached within the patch
    for (int k = 1; k <= lags; ++k) {
      const double rho = s.autocorrelation[k - 1];
      if (rho <= target) {
        s.correlation_length_px = (k - 1) + (previous - target) / (previous - rho);
        break;
      }
      previous = rho;
    }
  }
  return s;
}

TemporalCorrelation AnalyseTemporalCorrelation(const std::vector<float>& a_m,
                                               const std::vector<float>& b_m, int width,
                                               int height, const PinholeIntrinsics& intrinsics,
                                               const ErrorStructureOptions& options) {
  options.Validate("error_structure");
  CheckDepthSize(a_m, width, height);
  CheckDepthSize(b_m, width, height);
  const std::vector<Patch> patches_a =
      PlanarPatches(a_m, width, height, intrinsics, options, nullptr, nullptr);
  const std::vector<Patch> patches_b =
      PlanarPatches(b_m, width, height, intrinsics, options, nullptr, nullptr);
  // Both lists are in tiling order: a merge finds the windows kept in both frames.
  const std::vector<const Patch*> a = InlierPatches(patches_a, options);
  const std::vector<const Patch*> b = InlierPatches(patches_b, options);
  auto order = [width](const Patch& p) { return static_cast<long>(p.v0) * width + p.u0; };
  TemporalCorrelation t;
  double ab = 0, aa = 0, bb = 0;
  for (size_t i = 0, j = 0; i < a.size() && j < b.size();) {
    if (order(*a[i]) < order(*b[j])) {
      ++i;
    } else if (order(*b[j]) < order(*a[i])) {
      ++j;
    } else {
      ab += a[i]->residual.dot(b[j]->residual);
      aa += a[i]->residual.squaredNorm();
      bb += b[j]->residual.squaredNorm();
      ++t.patches;
      ++i;
      ++j;
    }
  }
  t.rho = aa > 0 && bb > 0 ? ab / std::sqrt(aa * bb) : kNaN;
  return t;
}

std::vector<float> SurfaceAlignedDepth(const std::vector<float>& a_m, const std::vector<float>& b_m,
                                       int width, int height, const PinholeIntrinsics& intrinsics,
                                       const Rigid3& b_T_a) {
  CheckDepthSize(a_m, width, height);
  CheckDepthSize(b_m, width, height);
  std::vector<float> out(a_m.size(), 0.0f);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const float z = a_m[static_cast<size_t>(v) * width + u];
      if (!(z > 0)) continue;
      const Eigen::Vector3d a_point(z * (u - intrinsics.cx) / intrinsics.fx,
                                    z * (v - intrinsics.cy) / intrinsics.fy, z);
      const Eigen::Vector3d b_point = b_T_a * a_point;
      if (!(b_point.z() > 0)) continue;
      const double ub = intrinsics.fx * b_point.x() / b_point.z() + intrinsics.cx;
      const double vb = intrinsics.fy * b_point.y() / b_point.z() + intrinsics.cy;
      const double iu = std::floor(ub + 0.5), iv = std::floor(vb + 0.5);
      if (!(iu >= 0 && iu < width && iv >= 0 && iv < height)) continue;
      out[static_cast<size_t>(v) * width + u] =
          b_m[static_cast<size_t>(iv) * width + static_cast<size_t>(iu)];
    }
  }
  return out;
}

nlohmann::json ToJson(const ErrorStructure& s) {
  return {{"missing_by_cause",
           {{"border", s.missing_border},
            {"shadow", s.missing_shadow},
            {"edge", s.missing_edge},
            {"range", s.missing_range},
            {"low_signal", s.missing_low_signal}}},
          {"shadow_band_px", s.shadow_band_px},
          {"edge_band_px", s.edge_band_px},
          {"shadow_band_across_px", s.shadow_band_across_px},
          {"edge_band_across_px", s.edge_band_across_px},
          {"patches", s.patches},
          {"noise_over_model", s.noise_over_model},
          {"noise_over_model_by_incidence_0_20_40_60_deg", s.noise_over_model_by_incidence},
          {"patches_by_incidence_0_20_40_60_deg", s.patches_by_incidence},
          {"autocorrelation", s.autocorrelation},
          {"autocorrelation_along_rows", s.autocorrelation_along_rows},
          {"autocorrelation_along_columns", s.autocorrelation_along_columns},
          {"correlation_length_px", s.correlation_length_px}};
}

std::string FormatRealismTable(const std::vector<std::string>& names,
                               const std::vector<ErrorStructure>& structures, size_t reference,
                               const std::vector<size_t>& rendered) {
  struct Statistic {
    std::string label;
    double (*value)(const ErrorStructure&);
  };
  const Statistic statistics[] = {
      {"missing, all causes [%]",
       [](const ErrorStructure& s) {
         return 100 * (s.missing_border + s.missing_shadow + s.missing_edge + s.missing_range +
                       s.missing_low_signal);
       }},
      {"missing, image border [%]", [](const ErrorStructure& s) { return 100 * s.missing_border; }},
      {"missing, shadow [%]", [](const ErrorStructure& s) { return 100 * s.missing_shadow; }},
      {"missing, edge [%]", [](const ErrorStructure& s) { return 100 * s.missing_edge; }},
      {"missing, range [%]", [](const ErrorStructure& s) { return 100 * s.missing_range; }},
      {"missing, low signal [%]",
       [](const ErrorStructure& s) { return 100 * s.missing_low_signal; }},
      {"shadow band width [px]", [](const ErrorStructure& s) { return s.shadow_band_px; }},
      {"edge band width [px]", [](const ErrorStructure& s) { return s.edge_band_px; }},
      {"shadow band across [px]", [](const ErrorStructure& s) { return s.shadow_band_across_px; }},
      {"edge band across [px]", [](const ErrorStructure& s) { return s.edge_band_across_px; }},
      {"small-patch noise / model", [](const ErrorStructure& s) { return s.noise_over_model; }},
      {"  ... incidence 0-20 deg",
       [](const ErrorStructure& s) { return s.noise_over_model_by_incidence[0]; }},
      {"  ... incidence 20-40 deg",
       [](const ErrorStructure& s) { return s.noise_over_model_by_incidence[1]; }},
      {"  ... incidence 40-60 deg",
       [](const ErrorStructure& s) { return s.noise_over_model_by_incidence[2]; }},
      {"residual autocorrelation lag 1",
       [](const ErrorStructure& s) {
         return s.autocorrelation.empty() ? kNaN : s.autocorrelation[0];
       }},
      {"  ... along the rows",
       [](const ErrorStructure& s) {
         return s.autocorrelation_along_rows.empty() ? kNaN : s.autocorrelation_along_rows[0];
       }},
      {"  ... along the columns",
       [](const ErrorStructure& s) {
         return s.autocorrelation_along_columns.empty() ? kNaN : s.autocorrelation_along_columns[0];
       }},
      {"residual autocorrelation lag 2",
       [](const ErrorStructure& s) {
         return s.autocorrelation.size() < 2 ? kNaN : s.autocorrelation[1];
       }},
      {"correlation length [px]", [](const ErrorStructure& s) { return s.correlation_length_px; }},
  };
  auto cell = [](double v) {
    if (!std::isfinite(v)) return std::string("-");
    char buffer[32];
    std::snprintf(buffer, sizeof(buffer), "%.2f", v);
    return std::string(buffer);
  };
  std::vector<std::string> header = names;
  for (size_t r : rendered) header.push_back(names[r] + " / " + names[reference]);
  header.push_back("goal");
  std::vector<std::vector<std::string>> rows;
  for (const Statistic& statistic : statistics) {
    std::vector<std::string> row{statistic.label};
    for (const ErrorStructure& s : structures) row.push_back(cell(statistic.value(s)));
    const double real = statistic.value(structures[reference]);
    for (size_t r : rendered) {
      const double value = statistic.value(structures[r]);
      row.push_back(real != 0 ? cell(value / real) : std::string("-"));
    }
    row.push_back("0.80-1.20");
    rows.push_back(std::move(row));
  }
  std::vector<size_t> widths(header.size() + 1, 0);
  for (const auto& row : rows) {
    for (size_t c = 0; c < row.size(); ++c) widths[c] = std::max(widths[c], row[c].size());
  }
  for (size_t c = 0; c < header.size(); ++c)
    widths[c + 1] = std::max(widths[c + 1], header[c].size());
  auto line = [&](const std::vector<std::string>& cells) {
    std::string text = cells[0] + std::string(widths[0] - cells[0].size(), ' ');
    for (size_t c = 1; c < cells.size(); ++c) {
      text += "  " + std::string(widths[c] - cells[c].size(), ' ') + cells[c];
    }
    return text + "\n";
  };
  std::vector<std::string> first{""};
  first.insert(first.end(), header.begin(), header.end());
  std::string table = line(first);
  for (const auto& row : rows) table += line(row);
  return table;
}

std::vector<float> ResampleDepthNearest(const std::vector<float>& depth_m,
                                        const PinholeIntrinsics& from,
                                        const PinholeIntrinsics& to) {
  CheckDepthSize(depth_m, from.width, from.height);
  if (!(from.fx > 0 && from.fy > 0 && to.fx > 0 && to.fy > 0) || to.width <= 0 ||
      to.height <= 0) {
    ThrowBadValue("intrinsics", "fx " + std::to_string(from.fx) + " -> " + std::to_string(to.fx),
                  "positive focal lengths and image sizes");
  }
  // The source column of every target column, the same in every row (-1: outside).
  std::vector<long> source_column(to.width);
  for (int u = 0; u < to.width; ++u) {
    const long x = std::lround(from.cx + from.fx * (u - to.cx) / to.fx);
    source_column[u] = x >= 0 && x < from.width ? x : -1;
  }
  std::vector<float> out(static_cast<size_t>(to.width) * to.height, 0.0f);
  for (int v = 0; v < to.height; ++v) {
    const long y = std::lround(from.cy + from.fy * (v - to.cy) / to.fy);
    if (y < 0 || y >= from.height) continue;
    for (int u = 0; u < to.width; ++u) {
      if (source_column[u] < 0) continue;
      out[static_cast<size_t>(v) * to.width + u] =
          depth_m[static_cast<size_t>(y) * from.width + source_column[u]];
    }
  }
  return out;
}

RgbImage DepthSideBySide(const std::vector<const std::vector<float>*>& depths_m, int width,
                         int height) {
  constexpr int kGap = 8;
  RgbImage image;
  const int count = static_cast<int>(depths_m.size());
  image.width = count * width + (count - 1) * kGap;
  image.height = height;
  image.rgb.assign(3 * static_cast<size_t>(image.width) * height, 255);
  for (int k = 0; k < count; ++k) {
    const std::vector<float>& depth = *depths_m[k];
    if (depth.size() != static_cast<size_t>(width) * height) {
      ThrowBadValue("depth image " + std::to_string(k), std::to_string(depth.size()) + " pixels",
                    std::to_string(width) + "x" + std::to_string(height) + " pixels");
    }
    for (int v = 0; v < height; ++v) {
      for (int u = 0; u < width; ++u) {
        const float z = depth[static_cast<size_t>(v) * width + u];
        uint8_t* out =
            &image.rgb[3 * (static_cast<size_t>(v) * image.width + k * (width + kGap) + u)];
        if (!ValidDepth(z)) {
          out[0] = 200;
          out[1] = out[2] = 0;
          continue;
        }
        // Inverse depth: equal steps of disparity look alike at every range.
        const double t = std::clamp((1.0 / z - 0.25) / (2.0 - 0.25), 0.0, 1.0);
        out[0] = out[1] = out[2] = static_cast<uint8_t>(std::lround(30 + 225 * t));
      }
    }
  }
  return image;
}

}  // namespace mmh::sim
