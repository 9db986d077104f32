#include "track/slider_reader.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "track/internal/frame_geometry.h"

namespace mmh::track {

SliderReader::SliderReader(const TrackSetup& setup, const SliderReaderOptions& options)
    : setup_(setup), options_(options) {
  options_.Validate("slider");
  setup_.Validate("setup");
  if (!setup_.has_like_box()) {
    throw InputError("setup: like_box_length is 0: there is no Like box to read the slider from");
  }
}

SliderReading SliderReader::Read(const RgbdFrame& frame, const Rigid3& camera_T_table) {
  SliderReading reading;
  const PinholeIntrinsics& k = frame.depth_intrinsics;
  const bool registered = internal::ColorRegisteredToDepth(frame);
  if (!registered) {
    reading.reason = "no colour image registered to the depth image";
    return reading;
  }
  // The box's image: its corners' projections, grown by the margin and the block's height.
  const double hx = setup_.like_box_length / 2 + options_.box_margin;
  const double hy = setup_.like_box_width / 2 + options_.box_margin;
  const double top = setup_.slider_block_size + options_.max_height_margin;
  const std::optional<ImageRect> box = internal::ProjectTableBox(
      Eigen::Vector3d(setup_.like_box_center_x - hx, setup_.like_box_center_y - hy, 0.0),
      Eigen::Vector3d(setup_.like_box_center_x + hx, setup_.like_box_center_y + hy, top),
      camera_T_table, k);
  if (!box) {
    reading.reason = "the Like box is behind the camera";
    return reading;
  }
  const int x0 = box->x0, y0 = box->y0, x1 = box->x1, y1 = box->y1;
  if (x1 <= x0 || y1 <= y0) {
    reading.reason = "the Like box is outside the image";
    return reading;
  }
  const cv::Mat rgb(k.height, k.width, CV_8UC3, const_cast<uint8_t*>(frame.rgb.data()));
  cv::Mat hsv, green;
  cv::cvtColor(rgb(cv::Rect(x0, y0, x1 - x0, y1 - y0)), hsv, cv::COLOR_RGB2HSV);
  cv::inRange(hsv, cv::Scalar(options_.hue_min, options_.saturation_min, options_.value_min),
              cv::Scalar(options_.hue_max, 255, 255), green);

  const Rigid3 table_T_camera = camera_T_table.Inverse();
  xs_.clear();
  // Per image row, the block's leftmost and rightmost pixels (table x grows with image u).
  std::vector<int> row_first(y1 - y0, -1), row_last(y1 - y0, -1);
  for (int v = y0; v < y1; ++v) {
    for (int u = x0; u < x1; ++u) {
      if (!green.at<uint8_t>(v - y0, u - x0)) continue;
      const uint16_t d = frame.depth[static_cast<size_t>(v) * k.width + u];
      if (d == 0) continue;
      const Eigen::Vector3d table_p = table_T_camera * k.BackProject(u, v, d * frame.depth_scale);
      if (table_p.z() < options_.min_height || table_p.z() > top ||
          std::abs(table_p.x() - setup_.like_box_center_x) > hx ||
          std::abs(table_p.y() - setup_.like_box_center_y) > hy) {
        continue;
      }
      xs_.push_back(static_cast<float>(table_p.x()));
      if (row_first[v - y0] < 0) row_first[v - y0] = u;
      row_last[v - y0] = u;
    }
  }
  reading.points = static_cast<int>(xs_.size());
  if (reading.points < options_.min_points) {
    reading.reason =
        "no green block in the Like box (" + std::to_string(reading.points) + " points)";
    return reading;
  }
  auto quantile = [&](double q) {
    const size_t i = std::min(xs_.size() - 1, static_cast<size_t>(q * (xs_.size() - 1) + 0.5));
    std::nth_element(xs_.begin(), xs_.begin() + i, xs_.end());
    return static_cast<double>(xs_[i]);
  };
  const double lo = quantile(options_.edge_quantile);
  const double hi = quantile(1 - options_.edge_quantile);
  reading.center_x = 0.5 * (lo + hi);
  // The hand moving the block may hide one of its ends: a row's end is hidden when the pixel just
  // beyond it is nearer the camera than the block (a finger in front), not farther (the table).
  // When the visible extent is short of the block and the hiding is on one side only, the other
  // end is the block's true edge and the centre lies half a block from it.
  const double size = setup_.slider_block_size;
  if (hi - lo < 0.9 * size) {
    const auto depth_at = [&](int u, int v) {
      return u >= 0 && u < k.width ? frame.depth[static_cast<size_t>(v) * k.width + u] : 0;
    };
    const auto hidden = [&](int v, int edge, int step) {
      const uint16_t block = depth_at(edge, v);
      for (int u = edge + step; std::abs(u - edge) <= 3; u += step) {
        const uint16_t d = depth_at(u, v);
        if (d == 0) continue;
        return static_cast<double>(block - d) * frame.depth_scale > 0.005;
      }
      return false;
    };
    int hidden_low = 0, hidden_high = 0, rows = 0;
    for (int v = y0; v < y1; ++v) {
      if (row_first[v - y0] < 0) continue;
      ++rows;
      hidden_low += hidden(v, row_first[v - y0], -1);
      hidden_high += hidden(v, row_last[v - y0], +1);
    }
    if (hidden_low > rows / 2 && hidden_low >= 2 * hidden_high) reading.center_x = hi - 0.5 * size;
    if (hidden_high > rows / 2 && hidden_high >= 2 * hidden_low) reading.center_x = lo + 0.5 * size;
  }
  reading.raw_value = setup_.SliderValue(reading.center_x);
  reading.value = std::clamp(reading.raw_value, -5.0, 5.0);
  reading.found = true;
  return reading;
}

}  // namespace mmh::track
