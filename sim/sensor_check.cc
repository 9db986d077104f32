#include "sim/sensor_check.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <string>

#include "core/error.h"
#include "sim/internal/depth_sample.h"
#include "core/options.h"

namespace mmh::sim {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using internal::Median;
using internal::ValidDepth;

bool InRange(double z, const SensorCheckOptions& options) {
  return z >= options.min_depth_m && z <= options.max_depth_m;
}

int BinIndex(double z, double width) { return static_cast<int>(std::floor(z / width)); }

// Largest of a few round units of which 95 % of the distinct values are whole multiples; 0 when
// none is (continuous values, e.g. depths converted from raw disparity).
double EstimateQuantum(const std::vector<double>& distinct) {
  if (distinct.size() < 10) return 0.0;
  static constexpr double kCandidates[] = {1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4};
  for (double q : kCandidates) {
    size_t multiples = 0;
    for (double z : distinct) {
      const double units = z / q;
      // Values arrive as float: 0.02 units covers their rounding up to 10 m at 0.1 mm.
      if (std::abs(units - std::round(units)) <= 0.02) ++multiples;
    }
    if (multiples >= 0.95 * distinct.size()) return q;
  }
  return 0.0;
}

std::string Format(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

std::string Format2(const char* format, double a, double b) {
  char buffer[96];
  std::snprintf(buffer, sizeof(buffer), format, a, b);
  return buffer;
}

}  // namespace

void SensorCheckOptions::Validate(const std::string& prefix) const {
  if (!std::isfinite(bin_width_m) || bin_width_m <= 0) {
    ThrowBadValue(prefix + ".bin_width_m", FormatNumber(bin_width_m), "a finite width > 0 m");
  }
  if (!std::isfinite(min_depth_m) || min_depth_m < 0) {
    ThrowBadValue(prefix + ".min_depth_m", FormatNumber(min_depth_m), "a finite depth >= 0 m");
  }
  if (!std::isfinite(max_depth_m) || max_depth_m <= min_depth_m) {
    ThrowBadValue(prefix + ".max_depth_m", FormatNumber(max_depth_m),
                  "a finite depth > min_depth_m (" + FormatNumber(min_depth_m) + " m)");
  }
  if (!std::isfinite(depth_quantum_m) || depth_quantum_m < 0) {
    ThrowBadValue(prefix + ".depth_quantum_m", FormatNumber(depth_quantum_m),
                  "a finite quantum >= 0 m (0 = estimate)");
  }
  if (!std::isfinite(min_step_quanta) || min_step_quanta < 0) {
    ThrowBadValue(prefix + ".min_step_quanta", FormatNumber(min_step_quanta), "a number >= 0");
  }
  if (min_pairs_per_bin < 1) {
    ThrowBadValue(prefix + ".min_pairs_per_bin", std::to_string(min_pairs_per_bin),
                  "an integer >= 1");
  }
  if (max_step_multiple < 1) {
    ThrowBadValue(prefix + ".max_step_multiple", std::to_string(max_step_multiple),
                  "an integer >= 1");
  }
  if (patch_size < 3 || patch_size > 63 || patch_size % 2 == 0) {
    ThrowBadValue(prefix + ".patch_size", std::to_string(patch_size),
                  "an odd window side in [3, 63] px");
  }
  if (!std::isfinite(max_incidence_deg) || max_incidence_deg <= 0 || max_incidence_deg > 90) {
    ThrowBadValue(prefix + ".max_incidence_deg", FormatNumber(max_incidence_deg),
                  "an angle in (0, 90] degrees");
  }
  intrinsics.Validate(prefix + ".intrinsics");
  calibration.Validate(prefix + ".calibration");
  noise.Validate(prefix + ".noise");
  if (!std::isfinite(raw_lattice_constant) || raw_lattice_constant <= 0) {
    ThrowBadValue(prefix + ".raw_lattice_constant", FormatNumber(raw_lattice_constant),
                  "a finite number > 0 m raw units (NYU: 351.3)");
  }
}

double MissingFraction(const std::vector<float>& depth_m) {
  if (depth_m.empty()) return 0.0;
  const auto missing =
      std::count_if(depth_m.begin(), depth_m.end(), [](float z) { return !ValidDepth(z); });
  return static_cast<double>(missing) / depth_m.size();
}

DepthStepLaw FitDepthStepLaw(const std::vector<float>& depth_m, const SensorCheckOptions& options) {
  DepthStepLaw law;
  law.model_k = 1.0 / options.calibration.lattice_constant();
  law.k = kNaN;
  law.fundamental_k = kNaN;
  std::vector<double> distinct;
  for (float z : depth_m) {
    if (ValidDepth(z) && InRange(z, options)) distinct.push_back(z);
  }
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  law.distinct_values = static_cast<int>(distinct.size());
  law.depth_quantum_m =
      options.depth_quantum_m > 0 ? options.depth_quantum_m : EstimateQuantum(distinct);

  struct Pair {
    double z_mid;  // (z_a + z_b) / 2 [m]
    double step;   // z_b - z_a [m]
    double k;      // step / (z_a z_b) [1/m]
    int bin;
    int multiple = 0;  // lattice steps, set once k0 is known
  };
  std::vector<Pair> pairs;
  const double min_step = options.min_step_quanta * law.depth_quantum_m;
  for (size_t i = 1; i < distinct.size(); ++i) {
    const double za = distinct[i - 1], zb = distinct[i];
    const double step = zb - za;
    if (step < min_step) continue;
    const double z_mid = 0.5 * (za + zb);
    pairs.push_back({z_mid, step, step / (za * zb), BinIndex(z_mid, options.bin_width_m)});
  }
  law.pairs = static_cast<int>(pairs.size());
  if (pairs.empty()) {
    law.warnings.push_back("no adjacent distinct depth values usable for the step law");
    return law;
  }
  std::map<int, std::vector<size_t>> bins;
  for (size_t i = 0; i < pairs.size(); ++i) bins[pairs[i].bin].push_back(i);

  // The fundamental step: the smallest median k_i of the bins dense enough to trust.
  for (const auto& [bin, members] : bins) {
    if (static_cast<int>(members.size()) < options.min_pairs_per_bin) continue;
    std::vector<double> ks;
    for (size_t i : members) ks.push_back(pairs[i].k);
    const double median = Median(ks);
    if (std::isnan(law.fundamental_k) || median < law.fundamental_k) law.fundamental_k = median;
  }
  if (std::isnan(law.fundamental_k)) {
    std::vector<double> ks;
    for (const Pair& p : pairs) ks.push_back(p.k);
    law.fundamental_k = Median(ks);
    law.warnings.push_back("no depth bin with " + std::to_string(options.min_pairs_per_bin) +
                           " pairs: the fundamental step is the median over all pairs");
  }
  std::vector<double> fitted;
  int fundamental = 0;
  for (Pair& p : pairs) {
    p.multiple = std::max(1, static_cast<int>(std::lround(p.k / law.fundamental_k)));
    if (p.multiple > options.max_step_multiple) continue;
    fitted.push_back(p.k / p.multiple);
    fundamental += p.multiple == 1;
  }
  law.pairs_fitted = static_cast<int>(fitted.size());
  law.k = Median(fitted);
  law.fundamental_fraction =
      fitted.empty() ? 0.0 : static_cast<double>(fundamental) / fitted.size();

  for (const auto& [bin, members] : bins) {
    std::vector<double> midpoints, steps, ks;
    int ones = 0;
    for (size_t i : members) {
      if (pairs[i].multiple > options.max_step_multiple) continue;  // a gap, not a step
      midpoints.push_back(pairs[i].z_mid);
      steps.push_back(pairs[i].step);
      ks.push_back(pairs[i].k);
      ones += pairs[i].multiple == 1;
    }
    if (steps.empty()) continue;
    DepthStepBin out;
    out.z_min_m = bin * options.bin_width_m;
    out.z_max_m = (bin + 1) * options.bin_width_m;
    out.pairs = static_cast<int>(steps.size());
    out.median_z_m = Median(midpoints);
    out.median_step_m = Median(steps);
    out.median_k = Median(ks);
    out.fundamental_fraction = static_cast<double>(ones) / steps.size();
    // At the pairs' depth, not the bin centre: the step grows as z^2 across the bin.
    out.model_step_m = LatticeStep(out.median_z_m, options.calibration);
    law.bins.push_back(out);
  }
  return law;
}

std::vector<NoiseBin> EstimatePatchNoise(const std::vector<float>& depth_m, int width, int height,
                                         const SensorCheckOptions& options, int* patches) {
  const int size = options.patch_size;
  const int half = size / 2;
  // Sum of du^2 over the window (the same for dv): with a full symmetric window the least-squares
  // plane decouples into c = mean, a = sum(du z) / sum(du^2), b = sum(dv z) / sum(dv^2).
  double sum_d2 = 0;
  for (int d = -half; d <= half; ++d) sum_d2 += static_cast<double>(size) * d * d;
  const int n = size * size;
  const PinholeIntrinsics& k = options.intrinsics;
  const double max_angle = options.max_incidence_deg * std::numbers::pi / 180.0;

  struct Patch {
    double z, sigma, angle;
  };
  std::map<int, std::vector<Patch>> bins;
  int count = 0;
  std::vector<double> window(n);
  for (int v0 = half; v0 + half < height; v0 += size) {
    for (int u0 = half; u0 + half < width; u0 += size) {
      bool complete = true;
      double sum = 0;
      for (int dv = -half; dv <= half && complete; ++dv) {
        for (int du = -half; du <= half; ++du) {
          const float z = depth_m[static_cast<size_t>(v0 + dv) * width + (u0 + du)];
          if (!ValidDepth(z) || !InRange(z, options)) {
            complete = false;
            break;
          }
          window[(dv + half) * size + (du + half)] = z;
          sum += z;
        }
      }
      if (!complete) continue;
      const double c = sum / n;
      double sum_du_z = 0, sum_dv_z = 0;
      for (int dv = -half; dv <= half; ++dv) {
        for (int du = -half; du <= half; ++du) {
          const double z = window[(dv + half) * size + (du + half)] - c;
          sum_du_z += du * z;
          sum_dv_z += dv * z;
        }
      }
      const double a = sum_du_z / sum_d2, b = sum_dv_z / sum_d2;
      double ssr = 0;
      for (int dv = -half; dv <= half; ++dv) {
        for (int du = -half; du <= half; ++du) {
          const double r = window[(dv + half) * size + (du + half)] - (a * du + b * dv + c);
          ssr += r * r;
        }
      }
      // Incidence angle: the plane's tangents from the back-projection
      // P(u, v) = ((u - cx) z / fx, (v - cy) z / fy, z) with z = a u + b v + c.
      const double x = (u0 - k.cx) / k.fx, y = (v0 - k.cy) / k.fy;
      const Eigen::Vector3d tangent_u((c + (u0 - k.cx) * a) / k.fx, y * a, a);
      const Eigen::Vector3d tangent_v(x * b, (c + (v0 - k.cy) * b) / k.fy, b);
      const Eigen::Vector3d normal = tangent_u.cross(tangent_v);
      const Eigen::Vector3d ray(x, y, 1.0);
      const double cosine = std::min(1.0, std::abs(normal.dot(ray)) / (normal.norm() * ray.norm()));
      const double angle = std::acos(cosine);
      if (!(angle <= max_angle)) continue;
      bins[BinIndex(c, options.bin_width_m)].push_back({c, std::sqrt(ssr / (n - 3)), angle});
      ++count;
    }
  }
  if (patches) *patches = count;

  std::vector<NoiseBin> result;
  for (const auto& [bin, members] : bins) {
    NoiseBin out;
    out.z_min_m = bin * options.bin_width_m;
    out.z_max_m = (bin + 1) * options.bin_width_m;
    out.patches = static_cast<int>(members.size());
    std::vector<double> residual, angle, sigma, quantisation, total;
    for (const Patch& p : members) {
      residual.push_back(p.sigma);
      angle.push_back(p.angle * 180.0 / std::numbers::pi);
      const double model = options.noise.Sigma(p.z, p.angle);
      const double step = LatticeStep(p.z, options.calibration) / std::sqrt(12.0);
      sigma.push_back(model);
      quantisation.push_back(step);
      total.push_back(std::hypot(model, step));
    }
    out.median_residual_m = Median(residual);
    out.median_incidence_deg = Median(angle);
    out.model_sigma_m = Median(sigma);
    out.model_quantisation_m = Median(quantisation);
    out.model_total_m = Median(total);
    result.push_back(out);
  }
  return result;
}

RawDisparityStatistics AnalyseRawDisparity(const std::vector<uint16_t>& raw,
                                           const SensorCheckOptions& options) {
  RawDisparityStatistics stats;
  stats.present = true;
  std::set<int> distinct;
  for (uint16_t r : raw) {
    if (r >= kRawInvalid) continue;
    ++stats.valid_pixels;
    distinct.insert(r);
  }
  stats.distinct_values = static_cast<int>(distinct.size());
  if (distinct.empty()) {
    stats.median_step = stats.implied_k = kNaN;
    return stats;
  }
  stats.min_raw = *distinct.begin();
  stats.max_raw = *distinct.rbegin();
  std::vector<double> steps;
  int previous = -1;
  for (int r : distinct) {
    if (previous >= 0) steps.push_back(r - previous);
    previous = r;
  }
  const auto ones = std::count(steps.begin(), steps.end(), 1.0);
  stats.unit_step_fraction = steps.empty() ? 0.0 : static_cast<double>(ones) / steps.size();
  stats.median_step = Median(steps);
  // z = C / (offset - raw): adjacent raw values r, r + m give dz = m z_a z_b / C.
  stats.implied_k = stats.median_step / options.raw_lattice_constant;
  return stats;
}

SensorStatistics ComputeSensorStatistics(const std::string& name, const std::vector<float>& depth_m,
                                         int width, int height, const SensorCheckOptions& options,
                                         const std::vector<uint16_t>* raw) {
  options.Validate("sensor_check");
  if (width < 1 || height < 1 ||
      depth_m.size() != static_cast<size_t>(width) * static_cast<size_t>(height)) {
    ThrowBadValue(name + ", depth", std::to_string(depth_m.size()) + " pixels",
                  std::to_string(width) + "x" + std::to_string(height) + " pixels");
  }
  if (raw && raw->size() != depth_m.size()) {
    ThrowBadValue(name + ", raw disparity", std::to_string(raw->size()) + " pixels",
                  std::to_string(depth_m.size()) + " (the depth image's size)");
  }
  SensorStatistics stats;
  stats.name = name;
  stats.width = width;
  stats.height = height;
  stats.missing_fraction = MissingFraction(depth_m);
  std::vector<double> valid;
  for (float z : depth_m) {
    if (ValidDepth(z)) valid.push_back(z);
  }
  stats.valid_pixels = static_cast<int>(valid.size());
  if (valid.empty()) {
    stats.depth_min_m = stats.depth_median_m = stats.depth_max_m = kNaN;
  } else {
    stats.depth_min_m = *std::min_element(valid.begin(), valid.end());
    stats.depth_max_m = *std::max_element(valid.begin(), valid.end());
    stats.depth_median_m = Median(std::move(valid));
  }
  stats.step_law = FitDepthStepLaw(depth_m, options);
  stats.noise_bins = EstimatePatchNoise(depth_m, width, height, options, &stats.noise_patches);
  if (raw) stats.raw = AnalyseRawDisparity(*raw, options);
  return stats;
}

std::vector<float> DepthMetresFromUnits(const std::vector<uint16_t>& values,
                                        double metres_per_unit) {
  std::vector<float> depth(values.size());
  for (size_t i = 0; i < values.size(); ++i) {
    depth[i] = static_cast<float>(values[i] * metres_per_unit);
  }
  return depth;
}

std::vector<float> DepthMetresFromNyuRaw(const std::vector<uint16_t>& raw) {
  std::vector<float> depth(raw.size(), 0.0f);
  for (size_t i = 0; i < raw.size(); ++i) {
    if (raw[i] >= kRawInvalid || raw[i] >= kNyuRawOffset) continue;
    depth[i] = static_cast<float>(kNyuDepthNumerator / (kNyuRawOffset - raw[i]));
  }
  return depth;
}

nlohmann::json ToJson(const SensorStatistics& s) {
  nlohmann::json step_bins = nlohmann::json::array();
  for (const auto& b : s.step_law.bins) {
    step_bins.push_back({{"z_min_m", b.z_min_m},
                         {"z_max_m", b.z_max_m},
                         {"pairs", b.pairs},
                         {"median_z_m", b.median_z_m},
                         {"median_step_m", b.median_step_m},
                         {"median_k", b.median_k},
                         {"fundamental_fraction", b.fundamental_fraction},
                         {"model_step_m", b.model_step_m}});
  }
  nlohmann::json noise_bins = nlohmann::json::array();
  for (const auto& b : s.noise_bins) {
    noise_bins.push_back({{"z_min_m", b.z_min_m},
                          {"z_max_m", b.z_max_m},
                          {"patches", b.patches},
                          {"median_residual_m", b.median_residual_m},
                          {"median_incidence_deg", b.median_incidence_deg},
                          {"model_sigma_m", b.model_sigma_m},
                          {"model_quantisation_m", b.model_quantisation_m},
                          {"model_total_m", b.model_total_m}});
  }
  const DepthStepLaw& law = s.step_law;
  nlohmann::json json = {{"name", s.name},
                         {"width", s.width},
                         {"height", s.height},
                         {"valid_pixels", s.valid_pixels},
                         {"missing_fraction", s.missing_fraction},
                         {"depth_min_m", s.depth_min_m},
                         {"depth_median_m", s.depth_median_m},
                         {"depth_max_m", s.depth_max_m},
                         {"step_law",
                          {{"depth_quantum_m", law.depth_quantum_m},
                           {"distinct_values", law.distinct_values},
                           {"pairs", law.pairs},
                           {"pairs_fitted", law.pairs_fitted},
                           {"fundamental_k", law.fundamental_k},
                           {"k", law.k},
                           {"model_k", law.model_k},
                           {"k_over_model", law.k / law.model_k},
                           {"fundamental_fraction", law.fundamental_fraction},
                           {"bins", step_bins},
                           {"warnings", law.warnings}}},
                         {"noise", {{"patches", s.noise_patches}, {"bins", noise_bins}}}};
  if (s.raw.present) {
    json["raw"] = {{"valid_pixels", s.raw.valid_pixels},
                   {"distinct_values", s.raw.distinct_values},
                   {"min_raw", s.raw.min_raw},
                   {"max_raw", s.raw.max_raw},
                   {"unit_step_fraction", s.raw.unit_step_fraction},
                   {"median_step", s.raw.median_step},
                   {"implied_k", s.raw.implied_k}};
  }
  return json;
}

std::string FormatSensorTable(const std::vector<SensorStatistics>& columns) {
  using Row = std::pair<std::string, std::vector<std::string>>;
  std::vector<Row> rows;
  auto add = [&](const std::string& label, const auto& cell) {
    Row row{label, {}};
    for (const auto& s : columns) row.second.push_back(cell(s));
    rows.push_back(std::move(row));
  };
  auto finite = [](double v) { return std::isfinite(v); };
  add("size [px]", [](const SensorStatistics& s) {
    return std::to_string(s.width) + "x" + std::to_string(s.height);
  });
  add("missing [%]",
      [](const SensorStatistics& s) { return Format("%.1f", 100 * s.missing_fraction); });
  add("depth min / median / max [m]", [](const SensorStatistics& s) {
    return Format("%.2f", s.depth_min_m) + " / " + Format("%.2f", s.depth_median_m) + " / " +
           Format("%.2f", s.depth_max_m);
  });
  add("distinct depth values",
      [](const SensorStatistics& s) { return std::to_string(s.step_law.distinct_values); });
  add("storage quantum [mm]", [](const SensorStatistics& s) {
    return s.step_law.depth_quantum_m > 0 ? Format("%g", 1000 * s.step_law.depth_quantum_m)
                                          : std::string("none");
  });
  add("step law k [1/m] (model)", [&](const SensorStatistics& s) {
    return finite(s.step_law.k) ? Format2("%.6f (%.6f)", s.step_law.k, s.step_law.model_k) : "-";
  });
  add("k / model k", [&](const SensorStatistics& s) {
    return finite(s.step_law.k) ? Format("%.3f", s.step_law.k / s.step_law.model_k) : "-";
  });
  add("1/k = s f b [px m] (model)", [&](const SensorStatistics& s) {
    return finite(s.step_law.k) ? Format2("%.1f (%.1f)", 1 / s.step_law.k, 1 / s.step_law.model_k)
                                : "-";
  });
  for (double z : {1.0, 2.4}) {
    add("step at " + Format("%g", z) + " m [mm] (model)", [&](const SensorStatistics& s) {
      return finite(s.step_law.k) ? Format2("%.2f (%.2f)", 1000 * s.step_law.k * z * z,
                                            1000 * s.step_law.model_k * z * z)
                                  : "-";
    });
  }
  add("pairs fitted / one step apart [%]", [](const SensorStatistics& s) {
    return std::to_string(s.step_law.pairs_fitted) + " / " +
           Format("%.0f", 100 * s.step_law.fundamental_fraction);
  });
  const bool any_raw = std::any_of(columns.begin(), columns.end(),
                                   [](const SensorStatistics& s) { return s.raw.present; });
  if (any_raw) {
    add("raw distinct / unit steps [%]", [](const SensorStatistics& s) {
      return s.raw.present ? std::to_string(s.raw.distinct_values) + " / " +
                                 Format("%.1f", 100 * s.raw.unit_step_fraction)
                           : std::string("-");
    });
    add("raw median step -> k [1/m]", [](const SensorStatistics& s) {
      return s.raw.present ? Format2("%g -> %.6f", s.raw.median_step, s.raw.implied_k)
                           : std::string("-");
    });
  }
  add("noise patches", [](const SensorStatistics& s) { return std::to_string(s.noise_patches); });

  // Bins aligned by their range across the columns (keyed in micrometres).
  auto key = [](double z) { return std::llround(z * 1e6); };
  std::map<long long, std::pair<double, double>> step_ranges, noise_ranges;
  for (const auto& s : columns) {
    for (const auto& b : s.step_law.bins) step_ranges[key(b.z_min_m)] = {b.z_min_m, b.z_max_m};
    for (const auto& b : s.noise_bins) noise_ranges[key(b.z_min_m)] = {b.z_min_m, b.z_max_m};
  }
  for (const auto& [k, range] : step_ranges) {
    add(Format2("step %.2f-%.2f m [mm] (model) n", range.first, range.second),
        [&, k = k](const SensorStatistics& s) {
          for (const auto& b : s.step_law.bins) {
            if (key(b.z_min_m) != k) continue;
            return Format2("%.2f (%.2f)", 1000 * b.median_step_m, 1000 * b.model_step_m) + " " +
                   std::to_string(b.pairs);
          }
          return std::string("-");
        });
  }
  for (const auto& [k, range] : noise_ranges) {
    add(Format2("noise %.2f-%.2f m [mm] (sigma_z/+quant.) n", range.first, range.second),
        [&, k = k](const SensorStatistics& s) {
          for (const auto& b : s.noise_bins) {
            if (key(b.z_min_m) != k) continue;
            return Format("%.2f", 1000 * b.median_residual_m) + " (" +
                   Format2("%.2f/%.2f", 1000 * b.model_sigma_m, 1000 * b.model_total_m) + ") " +
                   std::to_string(b.patches);
          }
          return std::string("-");
        });
  }
  add("warnings",
      [](const SensorStatistics& s) { return std::to_string(s.step_law.warnings.size()); });

  // Lay out: label column, then one column per statistics, each as wide as its widest cell.
  size_t label_width = 0;
  std::vector<size_t> widths(columns.size());
  for (size_t c = 0; c < columns.size(); ++c) widths[c] = columns[c].name.size();
  for (const auto& [label, cells] : rows) {
    label_width = std::max(label_width, label.size());
    for (size_t c = 0; c < cells.size(); ++c) widths[c] = std::max(widths[c], cells[c].size());
  }
  auto line = [&](const std::string& label, const std::vector<std::string>& cells) {
    std::string text = label + std::string(label_width - label.size(), ' ');
    for (size_t c = 0; c < cells.size(); ++c) {
      text += "  " + std::string(widths[c] - cells[c].size(), ' ') + cells[c];
    }
    while (!text.empty() && text.back() == ' ') text.pop_back();
    return text + "\n";
  };
  std::vector<std::string> names;
  for (const auto& s : columns) names.push_back(s.name);
  std::string table = line("", names);
  for (const auto& [label, cells] : rows) table += line(label, cells);
  return table;
}

}  // namespace mmh::sim
