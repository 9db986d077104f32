#include "track/table_plane.h"

#include <pcl/ModelCoefficients.h>
#include <pcl/console/print.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <Eigen/Geometry>
#include <cmath>
#include <mutex>
#include <numbers>
#include <vector>

#include "core/error.h"

namespace mmh::track {

std::optional<TablePlane> EstimateTablePlane(const RgbdFrame& frame,
                                             const TablePlaneOptions& options,
                                             const std::optional<Rigid3>& calibrated_camera_T_table,
                                             std::string* why) {
  const PinholeIntrinsics& k = frame.depth_intrinsics;
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  if (frame.depth.size() == static_cast<size_t>(k.pixel_count())) {
    for (int v = options.pixel_step / 2; v < k.height; v += options.pixel_step) {
      for (int u = options.pixel_step / 2; u < k.width; u += options.pixel_step) {
        const uint16_t d = frame.depth[static_cast<size_t>(v) * k.width + u];
        if (d == 0) continue;
        const Eigen::Vector3d p = k.BackProject(u, v, d * frame.depth_scale);
        cloud->push_back(pcl::PointXYZ(static_cast<float>(p.x()), static_cast<float>(p.y()),
                                       static_cast<float>(p.z())));
      }
    }
  }
  const size_t sampled = cloud->size();
  if (sampled < 50) {
    if (why)
      *why = "too few valid depth pixels for a plane (" + std::to_string(sampled) + " sampled)";
    return std::nullopt;
  }

  // RANSAC draws degenerate (collinear) samples now and then and simply draws again; PCL reports
  // each one on stderr at its error level, which would fill the terminal of `mmh run --quiet`.
  // Our own failures are reported through `why`.
  static std::once_flag quiet_pcl;
  std::call_once(quiet_pcl, [] { pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS); });
  std::vector<TablePlane> planes;
  pcl::SACSegmentation<pcl::PointXYZ> ransac;
  ransac.setOptimizeCoefficients(true);
  ransac.setModelType(pcl::SACMODEL_PLANE);
  ransac.setMethodType(pcl::SAC_RANSAC);
  ransac.setDistanceThreshold(options.distance_threshold);
  ransac.setMaxIterations(options.max_iterations);
  auto remaining = cloud;
  for (int i = 0; i < options.max_planes && remaining->size() >= 50; ++i) {
    pcl::PointIndices inliers;
    pcl::ModelCoefficients coefficients;
    ransac.setInputCloud(remaining);
    ransac.segment(inliers, coefficients);
    if (inliers.indices.size() < options.min_inlier_share * sampled ||
        coefficients.values.size() != 4) {
      break;
    }
    TablePlane plane;
    Eigen::Vector3d n(coefficients.values[0], coefficients.values[1], coefficients.values[2]);
    double offset = coefficients.values[3];
    const double norm = n.norm();
    n /= norm;
    offset /= norm;
    if (offset < 0) {  // the camera (the origin) on the positive side
      n = -n;
      offset = -offset;
    }
    plane.normal = n;
    plane.offset = offset;
    plane.inliers = static_cast<int>(inliers.indices.size());
    plane.inlier_share = static_cast<double>(inliers.indices.size()) / sampled;
    double sum = 0.0;
    for (int index : inliers.indices) {
      const auto& q = (*remaining)[index];
      sum += std::pow(plane.Height(Eigen::Vector3d(q.x, q.y, q.z)), 2);
    }
    plane.rms_distance = std::sqrt(sum / inliers.indices.size());
    planes.push_back(plane);
    // Remove the inliers and look for the next plane.
    std::vector<char> is_inlier(remaining->size(), 0);
    for (int index : inliers.indices) is_inlier[index] = 1;
    auto rest = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
    for (size_t j = 0; j < remaining->size(); ++j) {
      if (!is_inlier[j]) rest->push_back((*remaining)[j]);
    }
    remaining = rest;
  }
  if (planes.empty()) {
    if (why) *why = "RANSAC found no plane with enough inliers";
    return std::nullopt;
  }
  const double deg = std::numbers::pi / 180;
  const TablePlane* best = nullptr;
  if (calibrated_camera_T_table) {
    const Eigen::Vector3d up = calibrated_camera_T_table->rotation * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d origin = calibrated_camera_T_table->translation;
    double best_distance = 1e300;
    for (const TablePlane& plane : planes) {
      const double angle = std::acos(std::clamp(plane.normal.dot(up), -1.0, 1.0));
      const double distance = std::abs(plane.Height(origin));
      if (angle <= options.max_calibration_angle_deg * deg &&
          distance <= options.max_calibration_distance && distance < best_distance) {
        best = &plane;
        best_distance = distance;
      }
    }
    if (!best) {
      if (why) {
        *why = "none of the " + std::to_string(planes.size()) +
               " planes RANSAC found is within the calibration's tolerance of its table plane";
      }
      return std::nullopt;
    }
  } else if (options.largest) {
    for (const TablePlane& plane : planes) {
      if (!best || plane.inliers > best->inliers) best = &plane;
    }
  } else {
    const Eigen::Vector3d up(0, -1, 0);  // image up
    double best_angle = 1e300;
    for (const TablePlane& plane : planes) {
      best_angle = std::min(best_angle, std::acos(std::clamp(plane.normal.dot(up), -1.0, 1.0)));
    }
    for (const TablePlane& plane : planes) {
      const double angle = std::acos(std::clamp(plane.normal.dot(up), -1.0, 1.0));
      if (angle > best_angle + options.up_tolerance_deg * deg) continue;
      if (!best || plane.offset < best->offset) best = &plane;  // nearest the camera
    }
  }
  TablePlane result = *best;
  result.candidates = static_cast<int>(planes.size());
  return result;
}

Rigid3 TableFrameOnPlane(const TablePlane& plane, const std::optional<Rigid3>& calibrated) {
  const Eigen::Vector3d z = plane.normal;
  Eigen::Vector3d origin, x_hint;
  Eigen::Quaterniond rotation;
  if (calibrated) {
    const Eigen::Quaterniond align =
        Eigen::Quaterniond::FromTwoVectors(calibrated->rotation * Eigen::Vector3d::UnitZ(), z);
    rotation = (align * calibrated->rotation).normalized();
    origin = calibrated->translation - plane.Height(calibrated->translation) * z;
  } else {
    // The optical axis (0, 0, t) meets the plane at t = -offset / n_z.
    const double t = std::abs(z.z()) > 1e-6 ? -plane.offset / z.z() : 1.0;
    origin = Eigen::Vector3d(0, 0, t);
    Eigen::Vector3d x = Eigen::Vector3d::UnitX() - z * z.x();
    if (x.norm() < 1e-6) x = Eigen::Vector3d::UnitY() - z * z.y();
    x.normalize();
    const Eigen::Vector3d y = z.cross(x);
    Eigen::Matrix3d r;
    r.col(0) = x;
    r.col(1) = y;
    r.col(2) = z;
    rotation = Eigen::Quaterniond(r).normalized();
  }
  return Rigid3(rotation, origin);
}

}  // namespace mmh::track
