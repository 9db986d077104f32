#include "sim/depth_registration.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.h"
#include "core/simd.h"
#include "sim/internal/depth_sample.h"

namespace mmh::sim {

void DepthRegistrationOptions::Validate(const std::string& prefix) const {
  if (!(footprint_growth_px >= 0) || !std::isfinite(footprint_growth_px)) {
    ThrowBadValue(prefix + ".footprint_growth_px", FormatNumber(footprint_growth_px),
                  "a finite growth of 0 px or more");
  }
}

namespace {

// Cameras side by side: the destination columns [first_u[u], last_u[u]] (empty: first > last)
// whose centres c satisfy u0 - g <= c < u1 + g for source pixel u of a row, where
// u0 = left[u] + shift, u1 = right[u] + shift and shift = f_tx / z + cx moves a point at depth z
// from one camera to the other; missing depths cover nothing. IEEE operations only (ceil is
// exact), so every clone gives the same columns.
MMH_SIMD_CLONES void FootprintColumns(const float* z_row, const double* left, const double* right,
                                      int width, double f_tx, double cx, double g, int to_width,
                                      int32_t* first_u, int32_t* last_u) {
  const double last_column = to_width - 1;
  for (int u = 0; u < width; ++u) {
    const float z = z_row[u];
    const bool valid = internal::ValidDepth(z);
    const double shift = f_tx / (valid ? static_cast<double>(z) : 1.0) + cx;
    // Clamped before the conversion to int, so that no value outside int's range is converted.
    const double first = std::min(std::max(std::ceil((left[u] + shift) - g), 0.0), last_column + 1);
    const double last =
        std::max(std::min(std::ceil((right[u] + shift) + g) - 1, last_column), -1.0);
    first_u[u] = valid ? static_cast<int32_t>(first) : 1;
    last_u[u] = valid ? static_cast<int32_t>(last) : 0;
  }
}

}  // namespace

std::vector<float> RegisterDepth(const std::vector<float>& depth_m, const PinholeIntrinsics& from,
                                 const PinholeIntrinsics& to, const Rigid3& to_T_from,
                                 const DepthRegistrationOptions& options,
                                 std::vector<int32_t>* source) {
  options.Validate("registration");
  if (from.width <= 0 || from.height <= 0 || !(from.fx > 0) || !(from.fy > 0) ||
      depth_m.size() != static_cast<size_t>(from.width) * from.height) {
    ThrowBadValue("registration source", std::to_string(depth_m.size()) + " depths",
                  std::to_string(from.width) + " x " + std::to_string(from.height) +
                      " (the source intrinsics, positive focal lengths)");
  }
  if (to.width <= 0 || to.height <= 0 || !(to.fx > 0) || !(to.fy > 0)) {
    ThrowBadValue("registration destination",
                  std::to_string(to.width) + " x " + std::to_string(to.height),
                  "a positive size and focal lengths");
  }
  const float kFar = std::numeric_limits<float>::infinity();
  std::vector<float> out(static_cast<size_t>(to.width) * to.height, kFar);
  if (source != nullptr) source->assign(out.size(), -1);
  const Eigen::Matrix3d r = to_T_from.rotation.toRotationMatrix();
  const Eigen::Vector3d t = to_T_from.translation;
  const double g = options.footprint_growth_px;
  // Fill the destination centres c with u0 - g <= c < u1 + g (half-open, so abutting footprints
  // of a plane cover each centre once) in rows [row_begin, row_end), the nearest depth winning;
  // ties keep the lower source index (each destination row sees its sources in index order), so
  // the bytes depend neither on the order of rows nor on the threads.
  auto fill = [&](double u0, double u1, double v0, double v1, float depth, int32_t index,
                  int row_begin, int row_end) {
    const int first_u = std::max(0, static_cast<int>(std::ceil(u0 - g)));
    const int last_u = std::min(to.width - 1, static_cast<int>(std::ceil(u1 + g)) - 1);
    const int first_v = std::max(row_begin, static_cast<int>(std::ceil(v0 - g)));
    const int last_v = std::min(row_end - 1, static_cast<int>(std::ceil(v1 + g)) - 1);
    for (int y = first_v; y <= last_v; ++y) {
      const size_t row = static_cast<size_t>(y) * to.width;
      for (int x = first_u; x <= last_u; ++x) {
        if (depth < out[row + x]) {
          out[row + x] = depth;
          if (source != nullptr) (*source)[row + x] = index;
        }
      }
    }
  };
  // Cameras side by side along x with parallel axes (the Kinect's): a point keeps its depth, its
  // row's footprint is the same for every depth, and its column moves by f_to t_x / z.
  const bool side_by_side = (r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-12 &&
                            std::abs(t.y()) < 1e-12 && std::abs(t.z()) < 1e-12;
  if (side_by_side) {
    // Bands of destination rows in parallel: a source row's footprint spans the same destination
    // rows at every depth, so each band visits only the source rows that reach it. Per source
    // row the columns each footprint covers are found first (FootprintColumns, vectorised), then
    // filled row by row: a destination pixel still sees its sources in index order.
    const double su = to.fx / from.fx, sv = to.fy / from.fy;
    std::vector<double> left(from.width), right(from.width);
    for (int u = 0; u < from.width; ++u) {
      left[u] = su * (u - 0.5 - from.cx);
      right[u] = su * (u + 0.5 - from.cx);
    }
    const double f_tx = to.fx * t.x();
    auto fill_band = [&](const tbb::blocked_range<int>& band) {
      std::vector<int32_t> first_u(from.width), last_u(from.width);
      for (int v = 0; v < from.height; ++v) {
        const double v0 = sv * (v - 0.5 - from.cy) + to.cy, v1 = sv * (v + 0.5 - from.cy) + to.cy;
        if (std::ceil(v1 + g) <= band.begin() || std::ceil(v0 - g) >= band.end()) continue;
        const int first_v = std::max(band.begin(), static_cast<int>(std::ceil(v0 - g)));
        const int last_v = std::min(band.end() - 1, static_cast<int>(std::ceil(v1 + g)) - 1);
        const float* row = depth_m.data() + static_cast<size_t>(v) * from.width;
        FootprintColumns(row, left.data(), right.data(), from.width, f_tx, to.cx, g, to.width,
                         first_u.data(), last_u.data());
        for (int y = first_v; y <= last_v; ++y) {
          float* out_row = out.data() + static_cast<size_t>(y) * to.width;
          int32_t* source_row =
              source != nullptr ? source->data() + static_cast<size_t>(y) * to.width : nullptr;
          for (int u = 0; u < from.width; ++u) {
            const float z = row[u];
            for (int x = first_u[u]; x <= last_u[u]; ++x) {
              if (z < out_row[x]) {
                out_row[x] = z;
                if (source_row != nullptr) source_row[x] = v * from.width + u;
              }
            }
          }
        }
      }
    };
    tbb::parallel_for(tbb::blocked_range<int>(0, to.height, 16), fill_band);
  }
  for (int v = 0; v < from.height && !side_by_side; ++v) {
    for (int u = 0; u < from.width; ++u) {
      const float z = depth_m[static_cast<size_t>(v) * from.width + u];
      if (!internal::ValidDepth(z)) continue;
      auto moved = [&](double du, double dv) {
        return Eigen::Vector3d(r * Eigen::Vector3d((u + du - from.cx) / from.fx * z,
                                                   (v + dv - from.cy) / from.fy * z, z) +
                               t);
      };
      const Eigen::Vector3d centre = moved(0, 0);
      if (!(centre.z() > 0)) continue;
      // The footprint: the bounding box of the projected corners, exact for cameras side by side
      // (the Kinect's) whose footprints are rectangles.
      double u0 = std::numeric_limits<double>::infinity(), u1 = -u0, v0 = u0, v1 = -u0;
      bool behind = false;
      for (const double du : {-0.5, 0.5}) {
        for (const double dv : {-0.5, 0.5}) {
          const Eigen::Vector3d c = moved(du, dv);
          if (!(c.z() > 0)) {
            behind = true;
            continue;
          }
          const double x = to.fx * c.x() / c.z() + to.cx, y = to.fy * c.y() / c.z() + to.cy;
          u0 = std::min(u0, x);
          u1 = std::max(u1, x);
          v0 = std::min(v0, y);
          v1 = std::max(v1, y);
        }
      }
      if (behind) continue;
      fill(u0, u1, v0, v1, static_cast<float>(centre.z()), v * from.width + u, 0, to.height);
    }
  }
  for (float& z : out) {
    if (z == kFar) z = 0;
  }
  return out;
}

}  // namespace mmh::sim
