// SliderReaderOptions checked (track/slider_reader.h), apart from the reader (OpenCV): see
// track/proxy_tracker_options.cc.
#include <string>

#include "core/error.h"
#include "track/slider_reader.h"

namespace mmh::track {

void SliderReaderOptions::Validate(const std::string& prefix) const {
  auto in_range = [&](int value, int lo, int hi, const char* name) {
    if (value < lo || value > hi) {
      ThrowBadValue(prefix + "." + name, std::to_string(value),
                    "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    }
  };
  in_range(hue_min, 0, 180, "hue_min");
  in_range(hue_max, hue_min, 180, "hue_max");
  in_range(saturation_min, 0, 255, "saturation_min");
  in_range(value_min, 0, 255, "value_min");
  RequireNonNegative(min_height, prefix + ".min_height", "m");
  RequireNonNegative(max_height_margin, prefix + ".max_height_margin", "m");
  RequireNonNegative(box_margin, prefix + ".box_margin", "m");
  RequireNonNegative(depth_margin, prefix + ".depth_margin", "m");
  if (!(edge_quantile >= 0 && edge_quantile < 0.5)) {
    ThrowBadValue(prefix + ".edge_quantile", FormatNumber(edge_quantile), "a value in [0, 0.5)");
  }
  in_range(min_points, 1, 1000000, "min_points");
}

}  // namespace mmh::track
