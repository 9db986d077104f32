// SegmentationOptions checked (track/segmentation.h), apart from the segmenter (PCL, OpenCV): see
// track/proxy_tracker_options.cc.
#include <string>

#include "core/error.h"
#include "track/segmentation.h"

namespace mmh::track {

void SegmentationOptions::Validate(const std::string& prefix) const {
  if (pixel_step < 1 || pixel_step > 16) {
    ThrowBadValue(prefix + ".pixel_step", std::to_string(pixel_step), "an integer in [1, 16]");
  }
  RequireNonNegative(play_area_margin, prefix + ".play_area_margin", "m");
  RequireNonNegative(min_height, prefix + ".min_height", "m");
  RequirePositive(max_height, prefix + ".max_height", "m");
  if (!(max_height > min_height)) {
    ThrowBadValue(prefix + ".max_height", FormatNumber(max_height),
                  "more than min_height = " + FormatNumber(min_height) + " m");
  }
  if (background_frames < 1 || background_frames > 60000) {
    ThrowBadValue(prefix + ".background_frames", std::to_string(background_frames),
                  "an integer in [1, 60000]");
  }
  RequirePositive(background_tolerance, prefix + ".background_tolerance", "m");
  RequireNonNegative(background_margin, prefix + ".background_margin", "m");
  auto byte = [&](int value, const char* name) {
    if (value < 0 || value > 255) {
      ThrowBadValue(prefix + "." + name, std::to_string(value), "an 8-bit value in [0, 255]");
    }
  };
  byte(skin_cr_min, "skin_cr_min");
  byte(skin_cr_max, "skin_cr_max");
  byte(skin_cb_min, "skin_cb_min");
  byte(skin_cb_max, "skin_cb_max");
  if (skin_cr_min > skin_cr_max) {
    ThrowBadValue(prefix + ".skin_cr_min", std::to_string(skin_cr_min), "<= skin_cr_max");
  }
  if (skin_cb_min > skin_cb_max) {
    ThrowBadValue(prefix + ".skin_cb_min", std::to_string(skin_cb_min), "<= skin_cb_max");
  }
  if (background_interval < 1 || background_interval > 1000) {
    ThrowBadValue(prefix + ".background_interval", std::to_string(background_interval),
                  "an integer in [1, 1000]");
  }
  RequirePositive(window_margin, prefix + ".window_margin", "m");
  RequireNonNegative(max_depth_jump, prefix + ".max_depth_jump", "m");
  if (window_span < 0 || window_span > 32) {
    ThrowBadValue(prefix + ".window_span", std::to_string(window_span), "an integer in [0, 32]");
  }
  RequirePositive(window_tolerance, prefix + ".window_tolerance", "m");
  if (outline_span < 0 || outline_span > 32) {
    ThrowBadValue(prefix + ".outline_span", std::to_string(outline_span), "an integer in [0, 32]");
  }
  RequirePositive(outline_jump, prefix + ".outline_jump", "m");
  if (skin_grow_px < 0 || skin_grow_px > 8) {
    ThrowBadValue(prefix + ".skin_grow_px", std::to_string(skin_grow_px), "an integer in [0, 8]");
  }
  RequirePositive(skin_grow_depth, prefix + ".skin_grow_depth", "m");
  if (min_component_pixels < 1) {
    ThrowBadValue(prefix + ".min_component_pixels", std::to_string(min_component_pixels), ">= 1");
  }
}

}  // namespace mmh::track
