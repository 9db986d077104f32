#include "sim/silhouette_bleed.h"

#include <cmath>
#include <string>

#include "core/error.h"
#include "sim/internal/depth_sample.h"

namespace mmh::sim {
namespace {

using internal::Median;
using internal::ValidDepth;

struct SideSums {
  int ends = 0, bled = 0;
  double bleed = 0, erosion = 0;

  SideBleed Mean() const {
    SideBleed side;
    side.ends = ends;
    if (ends > 0) {
      side.bleed_px = bleed / ends;
      side.erosion_px = erosion / ends;
      side.bled_share = static_cast<double>(bled) / ends;
    }
    return side;
  }
};

// One row of the image with its mask and exclusion, and the end of a mask run measured outward
// along `out` (-1: the left end, +1: the right end).
class RowEnds {
 public:
  RowEnds(const float* depth, const uint8_t* mask, const uint8_t* excluded, int width,
          const SilhouetteBleedOptions& options)
      : depth_(depth), mask_(mask), excluded_(excluded), width_(width), options_(options) {}

  void Measure(int end, int out, SideSums& sums) const {
    const SilhouetteBleedOptions& o = options_;
    // Other objects' neighbourhoods anywhere from the deepest erosion to the background: not
    // measured.
    if (excluded_ != nullptr) {
      for (int k = -o.max_px; k <= o.background_to_px; ++k) {
        const int u = end + out * k;
        if (u >= 0 && u < width_ && excluded_[u] != 0) return;
      }
    }
    std::vector<double> inside;
    for (int k = 0; k < o.reference_px; ++k) {
      const int u = end - out * k;
      if (ValidDepth(depth_[u])) inside.push_back(depth_[u]);
    }
    if (inside.size() < 3) return;
    const double z_object = Median(inside);
    std::vector<double> background;
    for (int k = o.background_from_px; k <= o.background_to_px; ++k) {
      const int u = end + out * k;
      if (u < 0 || u >= width_) break;
      if (mask_[u] != 0) return;  // the object again (a concavity): no background here
      if (ValidDepth(depth_[u])) background.push_back(depth_[u]);
    }
    if (background.size() < 3 || Median(background) < z_object + o.min_step_m) return;
    int bleed = 0;
    for (int k = 1; k <= o.max_px; ++k) {
      const int u = end + out * k;
      if (u < 0 || u >= width_ || mask_[u] != 0) break;
      if (!ValidDepth(depth_[u]) || std::abs(depth_[u] - z_object) > o.depth_tolerance_m) break;
      ++bleed;
    }
    int erosion = 0;
    for (int k = 0; k < o.max_px; ++k) {
      const int u = end - out * k;
      if (u < 0 || u >= width_ || mask_[u] == 0) break;
      if (ValidDepth(depth_[u]) && depth_[u] <= z_object + o.depth_tolerance_m) break;
      ++erosion;
    }
    ++sums.ends;
    sums.bled += bleed > 0;
    sums.bleed += bleed;
    sums.erosion += erosion;
  }

 private:
  const float* depth_;
  const uint8_t* mask_;
  const uint8_t* excluded_;
  int width_;
  const SilhouetteBleedOptions& options_;
};

}  // namespace

void SilhouetteBleedOptions::Validate(const std::string& prefix) const {
  if (!(depth_tolerance_m > 0) || !std::isfinite(depth_tolerance_m)) {
    ThrowBadValue(prefix + ".depth_tolerance_m", FormatNumber(depth_tolerance_m),
                  "a finite tolerance above 0 m");
  }
  if (!(min_step_m >= 0) || !std::isfinite(min_step_m)) {
    ThrowBadValue(prefix + ".min_step_m", FormatNumber(min_step_m), "a finite step of 0 m or more");
  }
  if (reference_px < 3) {
    ThrowBadValue(prefix + ".reference_px", std::to_string(reference_px),
                  "3 or more (a median of at least 3 depths)");
  }
  if (min_run_px < reference_px) {
    ThrowBadValue(prefix + ".min_run_px", std::to_string(min_run_px),
                  "at least reference_px (" + std::to_string(reference_px) + ")");
  }
  if (max_px < 1) {
    ThrowBadValue(prefix + ".max_px", std::to_string(max_px), "1 or more");
  }
  if (background_from_px <= max_px) {
    ThrowBadValue(prefix + ".background_from_px", std::to_string(background_from_px),
                  "beyond max_px (" + std::to_string(max_px) + "): past any bleed");
  }
  if (background_to_px < background_from_px + 2) {
    ThrowBadValue(prefix + ".background_to_px", std::to_string(background_to_px),
                  "at least background_from_px + 2 (" + std::to_string(background_from_px + 2) +
                      "): 3 pixels or more");
  }
}

SilhouetteBleed MeasureSilhouetteBleed(const std::vector<float>& depth_m, int width, int height,
                                       std::span<const uint8_t> mask,
                                       const SilhouetteBleedOptions& options,
                                       std::span<const uint8_t> excluded) {
  options.Validate("silhouette_bleed");
  const size_t pixels = static_cast<size_t>(width) * height;
  if (width <= 0 || height <= 0 || depth_m.size() != pixels || mask.size() != pixels ||
      (!excluded.empty() && excluded.size() != pixels)) {
    ThrowBadValue("mask",
                  std::to_string(mask.size()) + " pixels, " + std::to_string(excluded.size()) +
                      " excluded and " + std::to_string(depth_m.size()) + " depths",
                  std::to_string(pixels) + " of each (" + std::to_string(width) + " x " +
                      std::to_string(height) + "; none excluded: 0)");
  }
  SideSums left, right;
  for (int v = 0; v < height; ++v) {
    const size_t row = static_cast<size_t>(v) * width;
    const RowEnds ends(depth_m.data() + row, mask.data() + row,
                       excluded.empty() ? nullptr : excluded.data() + row, width, options);
    for (int u = 0; u < width;) {
      if (mask[row + u] == 0) {
        ++u;
        continue;
      }
      const int first = u;
      while (u < width && mask[row + u] != 0) ++u;
      if (u - first < options.min_run_px) continue;
      ends.Measure(first, -1, left);
      ends.Measure(u - 1, +1, right);
    }
  }
  return {left.Mean(), right.Mean()};
}

}  // namespace mmh::sim
