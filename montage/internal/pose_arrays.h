// Internal to montage/: poses as a structure of arrays, so that the C_match loops of DTW and of the
// smoothness cost vectorise, and the SIMD cloning those loops use.
#pragma once

#include <vector>

#include "core/simd.h"
#include "core/trajectory.h"

namespace mmh::montage::internal {

// #frames entries each: quaternion (x, y, z, w) and translation (x, y, z).
struct PoseArrays {
  std::vector<double> qx, qy, qz, qw, tx, ty, tz;

  PoseArrays() = default;
  explicit PoseArrays(const Trajectory& trajectory) {
    Resize(trajectory.size());
    for (std::size_t i = 0; i < trajectory.size(); ++i) Set(i, trajectory.poses[i]);
  }

  // The frames `index[0], index[1], ...` of `from`.
  static PoseArrays Subset(const PoseArrays& from, const std::vector<int>& index) {
    PoseArrays out;
    out.Resize(index.size());
    for (std::size_t i = 0; i < index.size(); ++i) {
      const std::size_t k = static_cast<std::size_t>(index[i]);
      out.qx[i] = from.qx[k], out.qy[i] = from.qy[k], out.qz[i] = from.qz[k];
      out.qw[i] = from.qw[k], out.tx[i] = from.tx[k], out.ty[i] = from.ty[k];
      out.tz[i] = from.tz[k];
    }
    return out;
  }

  int size() const { return static_cast<int>(qx.size()); }

 private:
  void Resize(std::size_t n) {
    for (auto* v : {&qx, &qy, &qz, &qw, &tx, &ty, &tz}) v->resize(n);
  }
  void Set(std::size_t i, const Rigid3& pose) {
    qx[i] = pose.rotation.x(), qy[i] = pose.rotation.y(), qz[i] = pose.rotation.z();
    qw[i] = pose.rotation.w(), tx[i] = pose.translation.x(), ty[i] = pose.translation.y();
    tz[i] = pose.translation.z();
  }
};

}  // namespace mmh::montage::internal
