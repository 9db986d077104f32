// Metrics of a tracked 6-DoF trajectory against ground truth: per-frame rotation and translation
// errors, ADD (mean distance of the model's points under the two poses; Hinterstoisser et al.
// 2012) and ADD-S (mean distance to the nearest point, for symmetric objects; Xiang et al. 2018),
// success rates within thresholds, and failure runs (losses and how long until recovery).
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/rigid3.h"
#include "core/triangle_mesh.h"

namespace mmh::metrics {

struct PoseErrorOptions {
  // A frame succeeds when its rotation error is at most success_rotation_deg [deg] and its
  // translation error at most success_translation [m] (the 5 deg / 5 cm protocol of Shotton et
  // al. 2013, tightened to 1 cm for a hand-held proxy).
  double success_rotation_deg = 5.0;
  double success_translation = 0.01;
  // ADD / ADD-S success: below add_fraction of the model's diameter (BOP's 0.1).
  double add_fraction = 0.1;

  template <class V>
  void VisitFields(V& v) {
    v("success_rotation_deg", success_rotation_deg);
    v("success_translation", success_translation);
    v("add_fraction", add_fraction);
  }
  void Validate(const std::string& prefix) const;
};

struct FramePoseError {
  bool has_estimate = false;
  double rotation_deg = 0.0;  // angle of estimate^-1 * truth's rotation [deg]
  double translation = 0.0;   // distance of the origins [m]
  double add = 0.0;           // [m]
  double adds = 0.0;          // [m]
  bool success = false;       // within both thresholds (false without an estimate)
};

// The points ADD and ADD-S average over: the mesh's distinct vertices, evenly subsampled to at
// most max_points (#N by 3, model frame).
Eigen::Matrix<double, Eigen::Dynamic, 3> MetricPoints(const TriangleMesh& mesh,
                                                      int max_points = 500);

// Largest distance between two of the points [m] (the object's diameter).
double Diameter(const Eigen::Matrix<double, Eigen::Dynamic, 3>& points);

// Errors per frame: estimates[i] (nullopt: no pose, e.g. lost) against truth[i], both
// camera_T_object. Sizes must match (InputError).
std::vector<FramePoseError> ComputePoseErrors(
    const std::vector<std::optional<Rigid3>>& estimates, const std::vector<Rigid3>& truth,
    const Eigen::Matrix<double, Eigen::Dynamic, 3>& points, const PoseErrorOptions& options);

// A run of consecutive failed frames (no estimate, or outside the thresholds).
struct FailureRun {
  int first = 0;           // frame index
  int length = 0;          // frames
  bool recovered = false;  // a successful frame follows
};

struct TrackingSummary {
  int frames = 0;
  int frames_with_estimate = 0;
  // Over frames with an estimate.
  double median_rotation_deg = 0.0;
  double median_translation = 0.0;  // [m]
  double p95_rotation_deg = 0.0;
  double p95_translation = 0.0;  // [m]
  double mean_add = 0.0;         // [m]
  double mean_adds = 0.0;        // [m]
  // Over all frames (a frame without estimate fails).
  double success_rate = 0.0;
  double add_success_rate = 0.0;   // ADD < add_fraction * diameter
  double adds_success_rate = 0.0;  // ADD-S < add_fraction * diameter
  double diameter = 0.0;           // [m]
  std::vector<FailureRun> failures;
  int longest_failure = 0;  // frames
  bool all_recovered = true;
};

TrackingSummary SummarizeTracking(const std::vector<FramePoseError>& errors, double diameter,
                                  const PoseErrorOptions& options);

nlohmann::json ToJson(const TrackingSummary& summary);

// The q-quantile (0..1) of `values` by linear interpolation between order statistics (R's
// type 7, quantile()'s default); 0 for no values.
double Quantile(std::vector<double> values, double q);

}  // namespace mmh::metrics
