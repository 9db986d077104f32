// The tracker's motion model: the pose of the next frame from the measured ones. It continues the
// last measured step (the pose change between the last two measured frames) scaled by the steps'
// persistence. The least-squares factor that carries each measured step onto the next,
//
//   f = sum_k m^(K-k) d_k . d_(k-1) / sum_k m^(K-k) |d_(k-1)|^2,
//
// over the recent steps (memory m; d: the step in the proxy's frame about its centroid, i.e. the
// centroid's displacement and the rotation vector times the model's radius, so that both count as
// displacements of the model's surface [m]; f is exactly 1 for a constant step), is mapped to the
// persistence by a ramp: 0 below stop_below, 1 above continue_above. Smooth motion keeps f near 1
// (constant velocity); an unskilled animator's hand tremor (6-11 Hz, sampled at 30 frames/s:
// successive steps uncorrelated or reversed) brings it to 0 or below, where continuing the last
// step would double the prediction's error, and the tracking ICP's motion prior would hold the
// pose at the wrong place (Soldier take 4:0, frames 1600-1780: predictions 10-20 mm off, 18 failed
// frames; docs/tracker.md). The ramp, not f itself: the measured poses' noise makes successive
// steps anticorrelated and biases f low on smooth motion (the fast tumbling test, 4 mm and 3.8 deg
// a step, lost 3 frames with f as the persistence).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "core/rigid3.h"

namespace mmh::track {

struct MotionOptions {
  // false: constant velocity (persistence 1).
  bool adaptive = true;
  // Weight of the older steps' sums per frame, in [0, 1): about 1 / (1 - memory) steps count
  // (docs/tracker.md, "How the options were chosen").
  double memory = 0.75;
  // The persistence's ramp over the factor f: 0 at or below stop_below, 1 at or above
  // continue_above, linear between (equal: a step at that value).
  double stop_below = 0.25;
  double continue_above = 0.75;

  template <class V>
  void VisitFields(V& v) {
    v("adaptive", adaptive);
    v("memory", memory);
    v("stop_below", stop_below);
    v("continue_above", continue_above);
  }
  // memory in [0, 1), 0 <= stop_below <= continue_above <= 1 (InputError naming the key).
  void Validate(const std::string& prefix) const;
};

class MotionModel {
 public:
  // `centroid` and `radius` [m]: the model's, in its own frame (the steps are measured and
  // scaled about the centroid).
  MotionModel(const MotionOptions& options, const Eigen::Vector3d& centroid, double radius);

  // A measured pose (camera_T_proxy). `continues`: it follows the previous measured pose by one
  // frame's motion (false after a detection, a slide check's jump or the first frame: no step).
  void Measure(const Rigid3& camera_T_proxy, bool continues);
  // A frame without a measurement: the pose is carried on by the prediction, the step halved (a
  // hidden proxy is more likely to stop than to fly on); returns the carried pose.
  Rigid3 Coast();
  // Forgets everything (a loss).
  void Reset();

  // The pose the model expects on the next frame; nullopt before the first measurement.
  std::optional<Rigid3> Predict() const;
  // The last measured (or coasted) pose.
  const std::optional<Rigid3>& last() const { return last_; }
  // The least-squares factor f between successive steps (1 until two steps have been measured),
  // and the persistence in [0, 1] the prediction applies (its ramp; 1 when not adaptive).
  double factor() const;
  double persistence() const;

 private:
  MotionOptions options_;
  Rigid3 proxy_T_centroid_;
  double radius_;
  std::optional<Rigid3> last_;
  std::optional<Rigid3> velocity_;  // last * previous^-1 (camera frame, per frame)
  // The last measured step (#6; nullopt when the last frame made none) and the sums.
  std::optional<Eigen::Matrix<double, 6, 1>> last_step_;
  double numerator_ = 0.0, denominator_ = 0.0;
};

}  // namespace mmh::track
