#include "sim/anchor_noise.h"

#include <cmath>

#include "core/error.h"
#include "sim/internal/counter_random.h"

namespace mmh::sim {
namespace {

using internal::BoxMuller;
using internal::CounterHash;
using internal::Mix64;

// Noise streams of the per-frame key.
enum Stream : uint64_t { kShift = 1, kDisparity = 2, kDots = 3 };

uint32_t Key(uint64_t seed, int frame, uint64_t stream) {
  return static_cast<uint32_t>(
      Mix64(Mix64(seed ^ 0x616e63686f72ULL) ^ (static_cast<uint64_t>(frame) << 8) ^ stream));
}

// Every pixel moved by N(0, sigma) in u and v, the depth bilinearly interpolated there (missing
// where a neighbour is missing or the point leaves the image).
std::vector<float> ShiftLaterally(const std::vector<float>& depth_m, int width, int height,
                                  uint32_t key, double sigma_px) {
  std::vector<float> out(depth_m.size(), 0.0f);
  auto at = [&](int u, int v) { return depth_m[static_cast<size_t>(v) * width + u]; };
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const size_t p = static_cast<size_t>(v) * width + u;
      float du, dv;
      BoxMuller(CounterHash(key, static_cast<uint32_t>(p)), &du, &dv);
      const double x = u + sigma_px * du, y = v + sigma_px * dv;
      const int u0 = static_cast<int>(std::floor(x)), v0 = static_cast<int>(std::floor(y));
      if (u0 < 0 || v0 < 0 || u0 + 1 >= width || v0 + 1 >= height) continue;
      const double a = at(u0, v0), b = at(u0 + 1, v0), c = at(u0, v0 + 1), d = at(u0 + 1, v0 + 1);
      if (!(a > 0 && b > 0 && c > 0 && d > 0)) continue;
      const double fx = x - u0, fy = y - v0;
      out[p] =
          static_cast<float>((1 - fy) * ((1 - fx) * a + fx * b) + fy * ((1 - fx) * c + fx * d));
    }
  }
  return out;
}

// Barron and Malik's noise in raw disparity units, on the depth in centimetres (rounded to whole
// centimetres first where `round_to_cm`, as simkinect's code does).
void AddRawDisparityNoise(std::vector<float>& depth_m, uint32_t key, double sigma_raw,
                          bool round_to_cm) {
  for (size_t p = 0; p < depth_m.size(); ++p) {
    if (!(depth_m[p] > 0)) continue;
    const double z_cm = round_to_cm ? std::nearbyint(100.0 * depth_m[p]) : 100.0 * depth_m[p];
    if (!(z_cm > 0)) {
      depth_m[p] = 0;
      continue;
    }
    float n, unused;
    BoxMuller(CounterHash(key, static_cast<uint32_t>(p)), &n, &unused);
    const double raw = std::nearbyint(35130.0 / z_cm + sigma_raw * n + 0.5);
    depth_m[p] = raw > 0 ? static_cast<float>(35130.0 / raw / 100.0) : 0.0f;
  }
}

// Bohg et al.'s window filter over a dot pattern (anchor_noise.h), on disparities [px] (0 =
// missing).
std::vector<float> FilterOverDots(const std::vector<float>& disparity, int width, int height,
                                  const AnchorNoiseOptions& o) {
  const uint32_t dot_key = Key(o.dot_seed, 0, kDots);
  const auto threshold = static_cast<uint64_t>(o.dot_density * 4294967296.0);
  std::vector<uint8_t> dot(disparity.size());
  for (size_t p = 0; p < dot.size(); ++p) {
    dot[p] = CounterHash(dot_key, static_cast<uint32_t>(p)) < threshold;
  }
  const int half = o.window_px / 2;
  std::vector<float> out(disparity.size(), 0.0f);
  std::vector<double> filled(disparity.size(), 0.0);  // the weight a pixel was filled with
  for (int v = half; v + half < height; ++v) {
    for (int u = half; u + half < width; ++u) {
      const size_t centre = static_cast<size_t>(v) * width + u;
      if (!dot[centre] || !(disparity[centre] > 0)) continue;
      int dots = 0, valid_dots = 0, valid = 0;
      double sum = 0;
      for (int dv = -half; dv <= half; ++dv) {
        for (int du = -half; du <= half; ++du) {
          const size_t p = centre + static_cast<long>(dv) * width + du;
          dots += dot[p];
          if (disparity[p] > 0) {
            valid_dots += dot[p];
            ++valid;
            sum += disparity[p];
          }
        }
      }
      if (!(valid_dots > dots * o.valid_share)) continue;
      const double mean = sum / valid;
      int inlier_dots = 0;
      for (int dv = -half; dv <= half; ++dv) {
        for (int du = -half; du <= half; ++du) {
          const size_t p = centre + static_cast<long>(dv) * width + du;
          const double weight = 1.0 / std::max(1.0, 1.44 * (du * du + dv * dv));
          if (dot[p] && disparity[p] > 0 && std::abs(disparity[p] - mean) * weight < o.inlier_px) {
            ++inlier_dots;
          }
        }
      }
      if (!(inlier_dots > dots * o.valid_share)) continue;
      const float kept = static_cast<float>(std::nearbyint(8.0 * disparity[centre]) / 8.0);
      const int r = o.fill_radius_px;
      for (int dv = -r; dv <= r; ++dv) {
        for (int du = -r; du <= r; ++du) {
          const int r2 = du * du + dv * dv;
          if (r2 > r * r || v + dv < 0 || v + dv >= height || u + du < 0 || u + du >= width) {
            continue;
          }
          const size_t p = centre + static_cast<long>(dv) * width + du;
          const double weight = 1.0 / (1.0 + r2);
          if (filled[p] < weight) {
            filled[p] = weight;
            out[p] = kept;
          }
        }
      }
    }
  }
  return out;
}

}  // namespace

std::string AnchorName(AnchorModel model) {
  return model == AnchorModel::kIclNuim ? "ICL-NUIM" : "simkinect";
}

void AnchorNoiseOptions::Validate(const std::string& prefix) const {
  RequireNonNegative(shift_sigma_px, prefix + ".shift_sigma_px", "px");
  RequireNonNegative(raw_noise_sigma, prefix + ".raw_noise_sigma");
  RequirePositive(focal_px, prefix + ".focal_px", "px");
  RequirePositive(baseline_m, prefix + ".baseline_m", "m");
  if (window_px < 3 || window_px % 2 == 0) {
    ThrowBadValue(prefix + ".window_px", std::to_string(window_px),
                  "an odd window of 3 px or more");
  }
  RequireProbability(valid_share, prefix + ".valid_share");
  RequirePositive(inlier_px, prefix + ".inlier_px", "px");
  if (fill_radius_px < 0) {
    ThrowBadValue(prefix + ".fill_radius_px", std::to_string(fill_radius_px), "0 px or more");
  }
  if (!(dot_density > 0 && dot_density < 1)) {
    ThrowBadValue(prefix + ".dot_density", FormatNumber(dot_density), "dots per pixel in (0, 1)");
  }
}

std::vector<float> ApplyAnchorNoise(AnchorModel model, const std::vector<float>& exact_m, int width,
                                    int height, uint64_t seed, int frame,
                                    const AnchorNoiseOptions& options) {
  options.Validate("anchor");
  if (width <= 0 || height <= 0 || exact_m.size() != static_cast<size_t>(width) * height) {
    ThrowBadValue("anchor: depth image", std::to_string(exact_m.size()) + " pixels",
                  std::to_string(width) + " x " + std::to_string(height));
  }
  std::vector<float> depth_m =
      ShiftLaterally(exact_m, width, height, Key(seed, frame, kShift), options.shift_sigma_px);
  if (model == AnchorModel::kSimKinect) {
    const double fb = options.focal_px * options.baseline_m;
    std::vector<float> disparity(depth_m.size(), 0.0f);
    for (size_t p = 0; p < depth_m.size(); ++p) {
      if (depth_m[p] > 0)
        disparity[p] = static_cast<float>(std::nearbyint(8.0 * fb / depth_m[p]) / 8.0);
    }
    const std::vector<float> filtered = FilterOverDots(disparity, width, height, options);
    for (size_t p = 0; p < depth_m.size(); ++p) {
      depth_m[p] = filtered[p] > 0 ? static_cast<float>(fb / filtered[p]) : 0.0f;
    }
  }
  AddRawDisparityNoise(depth_m, Key(seed, frame, kDisparity), options.raw_noise_sigma,
                       model == AnchorModel::kSimKinect);
  return depth_m;
}

}  // namespace mmh::sim
