// The baseline of bench_track: the same segmentation as the tracker, then PCL's
// IterativeClosestPointWithNormals (point-to-plane, k-d tree correspondences) from the
// constant-velocity prediction, against the same model samples. No detection, no verification:
// it starts from a given pose. PCL stays in pcl_icp_baseline.cc.
#pragma once

#include <memory>
#include <string>

#include "core/rgbd_frame.h"
#include "core/rigid3.h"
#include "core/triangle_mesh.h"
#include "track/setup.h"

namespace mmh::track::internal {

struct PclIcpBaselineOptions {
  int max_iterations = 12;                    // PCL's setMaximumIterations
  double max_correspondence_distance = 0.02;  // [m]
  int max_points = 1500;                      // segmented points, evenly subsampled
};

class PclIcpBaseline {
 public:
  PclIcpBaseline(const TriangleMesh& model, const TrackSetup& setup,
                 const PclIcpBaselineOptions& options, const Rigid3& initial_camera_T_proxy);
  ~PclIcpBaseline();
  // camera_T_proxy for the frame (the prediction when too few points are segmented).
  Rigid3 Track(const RgbdFrame& frame);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mmh::track::internal
