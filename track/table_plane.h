// The table plane, estimated from one depth frame by RANSAC (PCL's SACSegmentation), and the
// table frame built on it.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "core/rgbd_frame.h"
#include "core/rigid3.h"

namespace mmh::track {

struct TablePlaneOptions {
  // Every pixel_step-th pixel of every pixel_step-th row feeds RANSAC [px].
  int pixel_step = 6;
  // RANSAC inlier distance [m] (about 3 sigma of the Kinect's axial noise at 1.5 m).
  double distance_threshold = 0.012;
  // RANSAC iterations per plane (PCL's setMaxIterations).
  int max_iterations = 300;
  // Planes extracted, largest first, among which the table is chosen.
  int max_planes = 3;
  // A plane needs this share of the sampled valid pixels.
  double min_inlier_share = 0.05;
  // With a calibrated camera_T_table: the table is the plane within this angle [deg] and distance
  // [m] of the calibrated one. Without: the plane whose normal is nearest the camera's up (-y);
  // among planes within up_tolerance_deg of that, the one nearest the camera (a table, not the
  // floor below it).
  double max_calibration_angle_deg = 15.0;
  double max_calibration_distance = 0.05;
  double up_tolerance_deg = 15.0;
  // Without a calibration, take the plane with the most inliers instead: a real recording whose
  // camera looks steeply down at a cluttered table (YCB-Video) has box tops whose normals are
  // nearer the image's up than the table's.
  bool largest = false;

  template <class V>
  void VisitFields(V& v) {
    v("pixel_step", pixel_step);
    v("distance_threshold", distance_threshold);
    v("max_iterations", max_iterations);
    v("max_planes", max_planes);
    v("min_inlier_share", min_inlier_share);
    v("max_calibration_angle_deg", max_calibration_angle_deg);
    v("max_calibration_distance", max_calibration_distance);
    v("up_tolerance_deg", up_tolerance_deg);
    v("largest", largest);
  }
  void Validate(const std::string& prefix) const;
};

// A plane n . p + offset = 0 in the depth camera's frame, n of unit length pointing to the camera's
// side (offset > 0: the camera is above it).
struct TablePlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0.0;        // [m], the camera's height above the plane
  int inliers = 0;            // sampled pixels within distance_threshold
  double inlier_share = 0.0;  // of the sampled valid pixels
  double rms_distance = 0.0;  // of the inliers [m]
  int candidates = 0;         // planes RANSAC extracted
  double Height(const Eigen::Vector3d& camera_p) const { return normal.dot(camera_p) + offset; }
};

// The table plane of `frame`, or nullopt (with the reason in *why) when no plane qualifies (e.g.
// all depth missing). `calibrated_camera_T_table`: see TablePlaneOptions. Deterministic (PCL's
// RANSAC with its fixed seed).
std::optional<TablePlane> EstimateTablePlane(const RgbdFrame& frame,
                                             const TablePlaneOptions& options,
                                             const std::optional<Rigid3>& calibrated_camera_T_table,
                                             std::string* why);

// camera_T_table on `plane`: with a calibration, its origin and x axis projected onto the plane
// (the smallest rotation taking its z axis to the plane's normal); without, the origin where the
// optical axis meets the plane and x along the camera's x axis projected onto it.
Rigid3 TableFrameOnPlane(const TablePlane& plane,
                         const std::optional<Rigid3>& calibrated_camera_T_table);

}  // namespace mmh::track
