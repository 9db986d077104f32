#include "sim/depth_registration.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.h"
#include "sim/internal/depth_sample.h"

namespace mmh::sim {

void DepthRegistrationOptions::Validate(const std::string& prefix) const {
  if (!(footprint_growth_px >= 0) || !std::isfinite(footprint_growth_px)) {
    ThrowBadValue(prefix + ".footprint_growth_px", FormatNumber(footprint_growth_px),
                  "a finite growth of 0 px or more");
  }
}

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
    // rows at every depth, so each band visits only the source rows that reach it.
    const double su = to.fx / from.fx, sv = to.fy / from.fy;
    auto fill_band = [&](const tbb::blocked_range<int>& band) {
      for (int v = 0; v < from.height; ++v) {
        const double v0 = sv * (v - 0.5 - from.cy) + to.cy, v1 = sv * (v + 0.5 - from.cy) + to.cy;
        if (std::ceil(v1 + g) <= band.begin() || std::ceil(v0 - g) >= band.end()) continue;
        for (int u = 0; u < from.width; ++u) {
          const float z = depth_m[static_cast<size_t>(v) * from.width + u];
          if (!internal::ValidDepth(z)) continue;
          const double shift = to.fx * t.x() / z + to.cx;
          fill(su * (u - 0.5 - from.cx) + shift, su * (u + 0.5 - from.cx) + shift, v0, v1, z,
               v * from.width + u, band.begin(), band.end());
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
