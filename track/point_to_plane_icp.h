// Robust point-to-plane ICP of camera-frame data points against a ProxyModel (Chen and Medioni
// 1992; Low 2004 for the linearisation): Gauss-Newton on proxy_T_camera with Huber weights,
// correspondences from the model's closest-point grid, restricted to model surfaces that face the
// camera, with a rejection distance that shrinks geometrically over the first iterations
// (coarse to fine).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <string>

#include "core/rigid3.h"
#include "track/proxy_model.h"

namespace mmh::track {

struct IcpOptions {
  // Gauss-Newton iterations at most.
  int max_iterations = 12;
  // Correspondence rejection distance [m]: start_distance at the first iteration, shrinking by a
  // constant factor to end_distance at shrink_iterations, end_distance after.
  double start_distance = 0.02;
  double end_distance = 0.006;
  int shrink_iterations = 4;
  // Huber threshold on the point-to-plane residual [m] (about the Kinect's axial noise at 1 m).
  double huber = 0.003;
  // Tukey's biweight instead of Huber's weight when > 0: a residual r of a point at depth z [m]
  // weighs (1 - (r / c)^2)^2 within c = tukey * z^2 [m] and nothing beyond (Beaton and Tukey
  // 1974). Huber's weight keeps a linear pull from every residual beyond its threshold; on a
  // structured-light frame a patch of a face displaced by a correlated disparity error (a few mm,
  // the size of a correlation window; docs/tracker.md, "Structured-light frames") pulls the face
  // with all its points, the redescending biweight lets it go. c grows as z^2 because the
  // disparity error's depth scale does (z^2 / (f b) per pixel of disparity; Khoshelham and Elberink
  // 2012). 0: Huber.
  double tukey = 0.0;
  // Converged when an update rotates less than this [rad] and moves less than this [m] (after the
  // distance has shrunk).
  double min_rotation = 2e-4;
  double min_translation = 1e-4;
  // A correspondence counts as an inlier (for the result's statistics) within this distance [m].
  double inlier_distance = 0.006;
  // Fit the extra points (skin-coloured ones) too, where they lie near the model; otherwise they
  // only count in the result's extra_inliers.
  bool fit_extra_points = true;
  // A Gaussian prior on the pose's deviation from the start pose (a motion model's prediction):
  // standard deviations of the rotation [deg] and translation [m]; 0: none. Each adds
  // (huber / sigma)^2 to the normal equations (the data's residuals are about huber), so it holds
  // only directions the data leaves (nearly) free: the roll of a box seen face-on while the hand
  // hides its top, which the data alone lets slide into poses the camera sees through.
  double prior_rotation_deg = 0.0;
  double prior_translation = 0.0;

  template <class V>
  void VisitFields(V& v) {
    v("max_iterations", max_iterations);
    v("start_distance", start_distance);
    v("end_distance", end_distance);
    v("shrink_iterations", shrink_iterations);
    v("huber", huber);
    v("tukey", tukey);
    v("min_rotation", min_rotation);
    v("min_translation", min_translation);
    v("inlier_distance", inlier_distance);
    v("fit_extra_points", fit_extra_points);
    v("prior_rotation_deg", prior_rotation_deg);
    v("prior_translation", prior_translation);
  }
  void Validate(const std::string& prefix) const;
};

struct IcpResult {
  Rigid3 proxy_T_camera;
  int iterations = 0;
  // Over the scored points (the first `scored` of the data): those with a correspondence within
  // inlier_distance on a camera-facing surface, their share, and their RMS point-to-plane
  // residual [m].
  int inliers = 0;
  double inlier_share = 0.0;
  // Of the other points: those within min(inlier_distance, extra_distance) of a camera-facing
  // model surface.
  int extra_inliers = 0;
  double rms = 0.0;
};

// Which data a model sample may match (colour consistency): bit kMatchesScored, the scored points
// (e.g. not skin-coloured); bit kMatchesExtra, the extra points (skin-coloured).
inline constexpr uint8_t kMatchesScored = 1, kMatchesExtra = 2;

// Aligns `points` (camera frame [m]) to the model from `proxy_T_camera`. The first `scored`
// points are the ones the statistics count (the rest, e.g. skin-coloured points, only help the fit
// where they lie within `extra_distance` of the model; pass points.size() for all).
// `sample_matches` (#S, empty: every sample matches every point): a point whose closest model
// sample may not match its kind has no correspondence (a skin-coloured point on the Soldier's blue
// trousers is the hand in front of them, not the proxy).
IcpResult AlignPointToPlane(const ProxyModel& model, std::span<const Eigen::Vector3f> points,
                            size_t scored, double extra_distance, const Rigid3& proxy_T_camera,
                            const IcpOptions& options,
                            std::span<const uint8_t> sample_matches = {});

}  // namespace mmh::track
