// Point-to-plane refinement with projective correspondences (the association of KinectFusion,
// Newcombe et al. 2011, against a sampled model): each data point is paired with the model surface
// its own camera ray meets first, i.e. the camera-facing model sample z-buffered into its pixel at
// the current pose. The Kinect's noise displaces a point along its ray, so this pairs it with the
// surface it measured; the closest sample (AlignPointToPlane) pairs a noisy point near an edge of a
// thin figure with the face beside it, or with a camera-facing face that another part of the model
// hides, and biases the fit (docs/tracker.md, "Projective refinement").
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <string>

#include "core/camera.h"
#include "core/rigid3.h"
#include "track/proxy_model.h"

namespace mmh::track {

struct ProjectiveOptions {
  // Gauss-Newton iterations; 0: off.
  int iterations = 3;
  // After an iteration whose step moved a part of the model by more than this in the image [px],
  // the model is z-buffered again (the correspondences change); after a smaller one the next
  // iteration keeps them. The z-buffer is most of the refinement's time.
  double rerender_px = 0.5;
  // A correspondence is rejected when the point lies farther than max_distance from its sample
  // [m] (the noise along the ray, sigma about 2.7 mm at 1.2 m with the disparity lattice and more
  // at grazing incidence, plus the sample's offset within its pixel) or farther than max_residual
  // from the sample's plane [m] (it measured another surface: beside a depth edge the front-most
  // neighbouring sample can be the occluder's). max_distance is wider than max_residual: a tight
  // cut along the ray trims the noise's tail on oblique faces and biases the fit.
  double max_distance = 0.015;
  double max_residual = 0.006;
  // Huber threshold on the point-to-plane residual [m].
  double huber = 0.003;
  // Stops when an update rotates less than this [rad] and moves less than this [m].
  double min_rotation = 2e-4;
  double min_translation = 1e-4;
  // The Gaussian prior on the deviation from the start pose, as IcpOptions' (standard deviations
  // [deg] and [m]; 0: none). It holds the directions a thin figure's data leaves nearly free.
  double prior_rotation_deg = 2.0;
  double prior_translation = 0.003;

  template <class V>
  void VisitFields(V& v) {
    v("iterations", iterations);
    v("rerender_px", rerender_px);
    v("max_distance", max_distance);
    v("max_residual", max_residual);
    v("huber", huber);
    v("min_rotation", min_rotation);
    v("min_translation", min_translation);
    v("prior_rotation_deg", prior_rotation_deg);
    v("prior_translation", prior_translation);
  }
  // iterations in [0, 100], max_distance, max_residual and huber > 0, the rest >= 0 (InputError
  // naming the key).
  void Validate(const std::string& prefix) const;
};

// Refines proxy_T_camera on `points` (camera frame [m], as measured at their pixels of an image
// with `intrinsics`): the first `scored` are the proxy's points; the rest (skin-coloured) only
// count within `extra_distance` of the model. `sample_matches` (#S or empty) as for
// AlignPointToPlane. Returns the refined proxy_T_camera (the start when too few points pair).
Rigid3 RefineProjective(const ProxyModel& model, const PinholeIntrinsics& intrinsics,
                        std::span<const Eigen::Vector3f> points, size_t scored,
                        double extra_distance, const Rigid3& proxy_T_camera,
                        const ProjectiveOptions& options,
                        std::span<const uint8_t> sample_matches = {});

}  // namespace mmh::track
