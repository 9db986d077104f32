#include "track/slider_reader.h"

#include <algorithm>
#include <cmath>
#include <limits>
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
  points_.clear();
  // A candidate block point: a green pixel at depth z [m] whose table position lies in the box,
  // between min_height and top.
  const auto add_point = [&](int u, int v, double z) {
    const Eigen::Vector3d table_p = table_T_camera * k.BackProject(u, v, z);
    if (table_p.z() < options_.min_height || table_p.z() > top ||
        std::abs(table_p.x() - setup_.like_box_center_x) > hx ||
        std::abs(table_p.y() - setup_.like_box_center_y) > hy) {
      return false;
    }
    points_.push_back({u, v, static_cast<float>(z), static_cast<float>(table_p.x()),
                       static_cast<float>(table_p.y())});
    return true;
  };
  const int width = x1 - x0;
  // Per pixel of a row: the depth [m] of a candidate there (0: none), and for a green pixel without
  // depth the nearest candidate's depth and distance in its run of green.
  std::vector<double> block_z(width), fill_z(width);
  std::vector<int> distance(width);
  constexpr int kFar = std::numeric_limits<int>::max();
  for (int v = y0; v < y1; ++v) {
    const uint8_t* mask = green.ptr<uint8_t>(v - y0);
    const uint16_t* depth = frame.depth.data() + static_cast<size_t>(v) * k.width;
    const size_t row_begin = points_.size();
    for (int i = 0; i < width; ++i) {
      block_z[i] = 0.0;
      if (!mask[i] || depth[x0 + i] == 0) continue;
      const double z = depth[x0 + i] * frame.depth_scale;
      if (add_point(x0 + i, v, z)) block_z[i] = z;
    }
    // The colour camera sees block pixels whose depth is missing: where a finger hides the block
    // from the IR camera beside the colour camera (the registration's gap), in the projector's
    // shadow, at the outline. Each takes the depth of the nearest candidate in its run of green
    // along the row (ties to the left), so that a row's extent is the colour image's.
    if (options_.fill_missing_depth) {
      for (int i = 0, last = -1; i < width; ++i) {
        distance[i] = kFar;
        if (!mask[i]) {
          last = -1;
        } else if (block_z[i] > 0) {
          last = i;
        } else if (last >= 0) {
          distance[i] = i - last;
          fill_z[i] = block_z[last];
        }
      }
      for (int i = width - 1, next = -1; i >= 0; --i) {
        if (!mask[i]) {
          next = -1;
        } else if (block_z[i] > 0) {
          next = i;
        } else if (next >= 0 && next - i < distance[i]) {
          distance[i] = next - i;
          fill_z[i] = block_z[next];
        }
      }
      for (int i = 0; i < width; ++i) {
        // A green pixel with a depth off the block (the table, the hand) is not filled.
        if (distance[i] == kFar || depth[x0 + i] != 0) continue;
        add_point(x0 + i, v, fill_z[i]);
      }
    }
    // A block matcher spreads a nearer surface's depth over its neighbours (a finger's over the
    // block's green pixels beside it), and such a pixel back-projects in front of the block. Along
    // a row the block's front face or top is at one depth and its side face recedes from it: a
    // candidate more than depth_margin nearer than the row's upper quartile of depth is an
    // occluder's, and is dropped.
    if (points_.size() > row_begin) {
      row_z_.clear();
      for (size_t j = row_begin; j < points_.size(); ++j) row_z_.push_back(points_[j].z);
      const size_t q = (3 * (row_z_.size() - 1) + 2) / 4;
      std::nth_element(row_z_.begin(), row_z_.begin() + q, row_z_.end());
      const float nearest = row_z_[q] - static_cast<float>(options_.depth_margin);
      points_.erase(std::remove_if(points_.begin() + row_begin, points_.end(),
                                   [&](const BlockPoint& p) { return p.z < nearest; }),
                    points_.end());
    }
  }
  reading.points = static_cast<int>(points_.size());
  if (reading.points < options_.min_points) {
    reading.reason =
        "no green block in the Like box (" + std::to_string(reading.points) + " points)";
    return reading;
  }
  xs_.clear();
  for (const BlockPoint& p : points_) xs_.push_back(p.x);
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
    // Per image row, the block's leftmost and rightmost points (table x grows with image u).
    struct RowEnds {
      const BlockPoint* first = nullptr;
      const BlockPoint* last = nullptr;
    };
    std::vector<RowEnds> rows_ends(y1 - y0);
    for (const BlockPoint& p : points_) {
      RowEnds& r = rows_ends[p.v - y0];
      if (!r.first || p.u < r.first->u) r.first = &p;
      if (!r.last || p.u > r.last->u) r.last = &p;
    }
    const auto hidden = [&](const BlockPoint& end, int step) {
      const uint16_t* depth = frame.depth.data() + static_cast<size_t>(end.v) * k.width;
      for (int u = end.u + step; std::abs(u - end.u) <= 3 && u >= 0 && u < k.width; u += step) {
        if (depth[u] == 0) continue;
        return end.z - depth[u] * frame.depth_scale > 0.005;
      }
      return false;
    };
    int hidden_low = 0, hidden_high = 0, rows = 0;
    for (const RowEnds& r : rows_ends) {
      if (!r.first) continue;
      ++rows;
      hidden_low += hidden(*r.first, -1);
      hidden_high += hidden(*r.last, +1);
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
