#include "track/segmentation.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "track/internal/frame_geometry.h"

namespace mmh::track {

namespace {

// Whether the depths `span` px before and after pixel i along a line exist and both lie within
// `jump` [raw units] of the pixel's (SegmentationOptions::outline_span: no depth step or hole).
bool InsideOutline(const uint16_t* depth, size_t i, size_t offset, bool inside, float jump) {
  if (!inside) return false;
  const uint16_t a = depth[i - offset], b = depth[i + offset];
  if (a == 0 || b == 0) return false;
  return std::abs(static_cast<float>(a) - depth[i]) <= jump &&
         std::abs(static_cast<float>(b) - depth[i]) <= jump;
}

// Whether the depths `span` px before and after pixel i along a line (`stride` 1: the row,
// `width`: the column; `before`/`after`: the neighbours lie in the image) exist and the pixel's
// depth lies within `tolerance` [raw units] of their mean (SegmentationOptions::window_span).
bool FlatAcross(const uint16_t* depth, size_t i, size_t offset, bool inside, float tolerance) {
  if (!inside) return false;
  const uint16_t a = depth[i - offset], b = depth[i + offset];
  if (a == 0 || b == 0) return false;
  return std::abs(static_cast<float>(a) + static_cast<float>(b) - 2.0f * depth[i]) <=
         2.0f * tolerance;
}

}  // namespace

Segmenter::Segmenter(const SegmentationOptions& options, const TrackSetup& setup)
    : options_(options), setup_(setup) {
  options_.Validate("segmentation");
  // The images here are small regions of one frame: OpenCV's worker threads (OpenMP in Debian's
  // build) cost more in wake-ups than they save, and the tracker is meant to run one per core.
  cv::setNumThreads(1);
}

void Segmenter::SetTable(const Rigid3& camera_T_table, const PinholeIntrinsics& intrinsics) {
  intrinsics_ = intrinsics;
  table_T_camera_ = camera_T_table.Inverse();
  // The play volume's image: the bounding box of its eight corners' projections.
  const double hx = setup_.play_area_width / 2 + options_.play_area_margin;
  const double hy = setup_.play_area_depth / 2 + options_.play_area_margin;
  const std::optional<ImageRect> box = internal::ProjectTableBox(
      Eigen::Vector3d(-hx, -hy, options_.min_height), Eigen::Vector3d(hx, hy, options_.max_height),
      camera_T_table, intrinsics);
  roi_ = box ? *box : ImageRect{0, 0, intrinsics.width, intrinsics.height};
  const int rw = roi_.x1 - roi_.x0, rh = roi_.y1 - roi_.y0;
  table_rays_.resize(static_cast<size_t>(std::max(rw, 0)) * std::max(rh, 0));
  const Eigen::Matrix3f rotation = table_T_camera_.rotation.toRotationMatrix().cast<float>();
  for (int v = 0; v < rh; ++v) {
    for (int u = 0; u < rw; ++u) {
      const Eigen::Vector3d ray = intrinsics.BackProject(roi_.x0 + u, roi_.y0 + v, 1.0);
      table_rays_[static_cast<size_t>(v) * rw + u] = rotation * ray.cast<float>();
    }
  }
  background_.assign(table_rays_.size(), 0.0f);
  running_.assign(table_rays_.size(), 0.0f);
  stable_.assign(table_rays_.size(), 0);
  has_table_ = true;
}

void Segmenter::Segment(const RgbdFrame& frame, Segmentation* out, const ImageRect* window) {
  out->points.clear();
  out->components.clear();
  out->outline.clear();
  out->skin_points.clear();
  out->component_sizes.clear();
  out->foreground_pixels = out->skin_pixels = out->dropped_pixels = 0;
  out->window_dropped_pixels = 0;
  // The region examined: the play volume's image, within the window when one is given.
  ImageRect region = roi_;
  if (window) {
    region.x0 = std::max(region.x0, window->x0);
    region.y0 = std::max(region.y0, window->y0);
    region.x1 = std::min(region.x1, window->x1);
    region.y1 = std::min(region.y1, window->y1);
  }
  out->roi = region;
  if (!has_table_ || region.empty()) return;
  const int width = intrinsics_.width, height = intrinsics_.height;
  const int rw = roi_.x1 - roi_.x0;  // row length of the per-ROI tables
  const int gw = region.x1 - region.x0, gh = region.y1 - region.y0;
  const int step = options_.pixel_step;
  const int mw = (gw + step - 1) / step, mh = (gh + step - 1) / step;

  // Skin, where the colour image is registered to the depth image.
  cv::Mat skin;
  const bool registered = internal::ColorRegisteredToDepth(frame);
  if (options_.skin && registered) {
    const cv::Mat rgb(height, width, CV_8UC3, const_cast<uint8_t*>(frame.rgb.data()));
    cv::Mat ycrcb;
    cv::cvtColor(rgb(cv::Rect(region.x0, region.y0, gw, gh)), ycrcb, cv::COLOR_RGB2YCrCb);
    cv::inRange(ycrcb, cv::Scalar(0, options_.skin_cr_min, options_.skin_cb_min),
                cv::Scalar(255, options_.skin_cr_max, options_.skin_cb_max), skin);
  }

  // The play volume, before the background: mask 1 = proxy candidate, 2 = skin.
  mask_.assign(static_cast<size_t>(mw) * mh, 0);
  const Eigen::Vector3f origin = table_T_camera_.translation.cast<float>();
  const float hx = static_cast<float>(setup_.play_area_width / 2 + options_.play_area_margin);
  const float hy = static_cast<float>(setup_.play_area_depth / 2 + options_.play_area_margin);
  const float z0 = static_cast<float>(options_.min_height);
  const float z1 = static_cast<float>(options_.max_height);
  const float scale = static_cast<float>(frame.depth_scale);
  const float margin = static_cast<float>(options_.background_margin);
  for (int my = 0; my < mh; ++my) {
    const int y = region.y0 + my * step;
    const uint16_t* row = frame.depth.data() + static_cast<size_t>(y) * width;
    const size_t table_row = static_cast<size_t>(y - roi_.y0) * rw - roi_.x0;
    for (int mx = 0; mx < mw; ++mx) {
      const int x = region.x0 + mx * step;
      const uint16_t d = row[x];
      if (d == 0) continue;
      const float z = d * scale;
      const size_t i = table_row + x;
      const Eigen::Vector3f table_p = z * table_rays_[i] + origin;
      if (table_p.z() < z0 || table_p.z() > z1 || std::abs(table_p.x()) > hx ||
          std::abs(table_p.y()) > hy) {
        continue;
      }
      if (options_.background && background_[i] > 0 && z > background_[i] - margin) continue;
      const bool is_skin = !skin.empty() && skin.at<uint8_t>(y - region.y0, x - region.x0) != 0;
      mask_[static_cast<size_t>(my) * mw + mx] = is_skin ? 2 : 1;
      ++out->foreground_pixels;
    }
  }
  if (out->foreground_pixels == 0) return;
  // The hand's depth past its colour outline (SegmentationOptions::skin_grow_px): a candidate
  // touching a skin pixel at about its depth becomes skin, skin_grow_px times over. Each pass reads
  // the previous pass's mask, so the result does not depend on the scan order.
  if (options_.skin_grow_px > 0 && !skin.empty()) {
    const float near = static_cast<float>(options_.skin_grow_depth) / scale;
    auto depth_at = [&](int mx, int my) -> float {
      return frame
          .depth[static_cast<size_t>(region.y0 + my * step) * width + region.x0 + mx * step];
    };
    // Whether a skin pixel of `mask` touches (mx, my) within `near` of its depth.
    auto touches_skin = [&](const std::vector<uint8_t>& mask, int mx, int my) {
      const float d = depth_at(mx, my);
      for (int ny = std::max(0, my - 1); ny <= std::min(mh - 1, my + 1); ++ny) {
        for (int nx = std::max(0, mx - 1); nx <= std::min(mw - 1, mx + 1); ++nx) {
          if (mask[static_cast<size_t>(ny) * mw + nx] == 2 &&
              std::abs(depth_at(nx, ny) - d) <= near) {
            return true;
          }
        }
      }
      return false;
    };
    std::vector<uint8_t> grown;
    for (int pass = 0; pass < options_.skin_grow_px; ++pass) {
      grown = mask_;
      for (int my = 0; my < mh; ++my) {
        for (int mx = 0; mx < mw; ++mx) {
          const size_t i = static_cast<size_t>(my) * mw + mx;
          if (mask_[i] == 1 && touches_skin(mask_, mx, my)) grown[i] = 2;
        }
      }
      mask_.swap(grown);
    }
  }

  // Connected components; small ones are noise (flying pixels at edges, speckle).
  std::vector<int> labels, areas;
  if (options_.max_depth_jump > 0) {
    DepthLimitedComponents(frame, region, mw, mh, &labels, &areas);
  } else {
    const cv::Mat mask(mh, mw, CV_8U, mask_.data());
    cv::Mat cv_labels, stats, centroids;
    const int count =
        cv::connectedComponentsWithStats(mask, cv_labels, stats, centroids, 8, CV_32S);
    labels.assign(cv_labels.begin<int>(), cv_labels.end<int>());
    areas.resize(count);
    for (int c = 0; c < count; ++c) areas[c] = stats.at<int>(c, cv::CC_STAT_AREA);
  }
  const int count = static_cast<int>(areas.size());
  std::vector<int> order;
  for (int c = 1; c < count; ++c) {
    if (areas[c] >= options_.min_component_pixels) {
      order.push_back(c);
    } else {
      out->dropped_pixels += areas[c];
    }
  }
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return areas[a] > areas[b]; });
  std::vector<int> rank(count, -1);
  for (size_t r = 0; r < order.size(); ++r) {
    rank[order[r]] = static_cast<int>(r);
    out->component_sizes.push_back(areas[order[r]]);
  }
  const float inverse_fx = static_cast<float>(1 / intrinsics_.fx);
  const float inverse_fy = static_cast<float>(1 / intrinsics_.fy);
  const float cx = static_cast<float>(intrinsics_.cx), cy = static_cast<float>(intrinsics_.cy);
  const int span = options_.window_span;
  const float window_tolerance = static_cast<float>(options_.window_tolerance);
  for (int my = 0; my < mh; ++my) {
    const int y = region.y0 + my * step;
    for (int mx = 0; mx < mw; ++mx) {
      const uint8_t m = mask_[static_cast<size_t>(my) * mw + mx];
      if (m == 0) continue;
      const int r = rank[labels[static_cast<size_t>(my) * mw + mx]];
      if (r < 0) continue;
      const int x = region.x0 + mx * step;
      const size_t pixel = static_cast<size_t>(y) * width + x;
      const float z = frame.depth[pixel] * scale;
      if (m == 1 && span > 0) {
        const float tolerance = window_tolerance * z * z / scale;
        if (!FlatAcross(frame.depth.data(), pixel, span, x >= span && x + span < width,
                        tolerance) ||
            !FlatAcross(frame.depth.data(), pixel, static_cast<size_t>(span) * width,
                        y >= span && y + span < height, tolerance)) {
          ++out->window_dropped_pixels;
          continue;
        }
      }
      const Eigen::Vector3f p((x - cx) * inverse_fx * z, (y - cy) * inverse_fy * z, z);
      if (m == 2) {
        out->skin_points.push_back(p);
        ++out->skin_pixels;
      } else {
        out->points.push_back(p);
        out->components.push_back(r);
        if (options_.outline_span > 0) {
          const int o = options_.outline_span;
          const float jump = static_cast<float>(options_.outline_jump) * z * z / scale;
          out->outline.push_back(
              !InsideOutline(frame.depth.data(), pixel, o, x >= o && x + o < width, jump) ||
              !InsideOutline(frame.depth.data(), pixel, static_cast<size_t>(o) * width,
                             y >= o && y + o < height, jump));
        }
      }
    }
  }
}

void Segmenter::DepthLimitedComponents(const RgbdFrame& frame, const ImageRect& region, int mw,
                                       int mh, std::vector<int>* labels,
                                       std::vector<int>* areas) const {
  // Union-find over the mask's pixels, joining 8-neighbours (as OpenCV's components do) whose
  // depths differ by at most max_depth_jump; labels are numbered in raster order of each
  // component's first pixel (0: background), as OpenCV numbers them.
  const int step = options_.pixel_step, width = intrinsics_.width;
  const uint16_t jump = static_cast<uint16_t>(
      std::min(65535.0, std::floor(options_.max_depth_jump / frame.depth_scale)));
  const size_t n = static_cast<size_t>(mw) * mh;
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  auto depth = [&](int mx, int my) {
    return frame.depth[static_cast<size_t>(region.y0 + my * step) * width + region.x0 + mx * step];
  };
  // A pixel at a depth step (some 8-neighbour's depth differs by more than the jump) joins no
  // other: the sensor interpolates across an object's outline (flying pixels), which would
  // otherwise bridge the step in small jumps.
  auto at_step = [&](int mx, int my, uint16_t d) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int nx = mx + dx, ny = my + dy;
        if (nx < 0 || ny < 0 || nx >= mw || ny >= mh) continue;
        const uint16_t e = depth(nx, ny);
        if (e != 0 && (d > e ? d - e : e - d) > jump) return true;
      }
    }
    return false;
  };
  for (int my = 0; my < mh; ++my) {
    for (int mx = 0; mx < mw; ++mx) {
      const int i = my * mw + mx;
      if (mask_[i] == 0) continue;
      const uint16_t d = depth(mx, my);
      if (at_step(mx, my, d)) continue;
      // The neighbours already visited: left, upper left, upper, upper right.
      const int neighbours[4][2] = {{-1, 0}, {-1, -1}, {0, -1}, {1, -1}};
      for (const auto& [dx, dy] : neighbours) {
        const int nx = mx + dx, ny = my + dy;
        if (nx < 0 || ny < 0 || nx >= mw) continue;
        const int j = ny * mw + nx;
        if (mask_[j] == 0) continue;
        const uint16_t e = depth(nx, ny);
        if ((d > e ? d - e : e - d) > jump || at_step(nx, ny, e)) continue;
        const int a = find(i), b = find(j);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
      }
    }
  }
  labels->assign(n, 0);
  areas->assign(1, 0);
  std::vector<int> label_of_root(n, 0);
  for (size_t i = 0; i < n; ++i) {
    if (mask_[i] == 0) continue;
    const int root = find(static_cast<int>(i));
    if (label_of_root[root] == 0) {
      label_of_root[root] = static_cast<int>(areas->size());
      areas->push_back(0);
    }
    (*labels)[i] = label_of_root[root];
    ++(*areas)[label_of_root[root]];
  }
}

void Segmenter::UpdateBackground(const RgbdFrame& frame, const ImageRect& exclude) {
  if (!has_table_ || !options_.background) return;
  // Every background_interval-th call learns; stability is counted in learning calls.
  if (background_calls_++ % options_.background_interval != 0) return;
  const int needed = (options_.background_frames + options_.background_interval - 1) /
                     options_.background_interval;
  const int width = intrinsics_.width;
  const int rw = roi_.x1 - roi_.x0, rh = roi_.y1 - roi_.y0;
  const float scale = static_cast<float>(frame.depth_scale);
  const float tolerance = static_cast<float>(options_.background_tolerance);
  const float margin = static_cast<float>(options_.background_margin);
  const int step = options_.pixel_step;
  for (int v = 0; v < rh; v += step) {
    const int y = roi_.y0 + v;
    const bool row_excluded = y >= exclude.y0 && y < exclude.y1;
    for (int u = 0; u < rw; u += step) {
      const int x = roi_.x0 + u;
      if (row_excluded && x >= exclude.x0 && x < exclude.x1) continue;
      const uint16_t d = frame.depth[static_cast<size_t>(y) * width + x];
      if (d == 0) continue;
      const float z = d * scale;
      const size_t i = static_cast<size_t>(v) * rw + u;
      if (background_[i] > 0 && z > background_[i] + margin) background_[i] = 0;  // uncovered
      if (stable_[i] > 0 && std::abs(z - running_[i]) <= tolerance) {
        if (stable_[i] < 65535) ++stable_[i];
        running_[i] += (z - running_[i]) / std::min<float>(stable_[i], 32.0f);
        if (stable_[i] >= needed) background_[i] = running_[i];
      } else {
        running_[i] = z;
        stable_[i] = 1;
      }
    }
  }
}

}  // namespace mmh::track
