// The tracker's output filter: a speed-adaptive low-pass on the reported poses, the 1€ filter of
// Casiez, Roussel and Vogel (CHI 2012, "1€ Filter: A Simple Speed-based Low-pass Filter for Noisy
// Input in Interactive Systems") on SE(3). Block-matching depth errors are spatially correlated,
// so the per-frame pose jitters by about 1.5 deg on structured-light frames (docs/tracker.md,
// "Output filter"): a viewer sees that as jerks, while the animator's motion is slower than the
// jitter. Each step, with dt the frame period and the exponential smoothing factor
//
//   alpha(f_c) = 1 / (1 + 1 / (2 pi f_c dt)),
//
// low-passes the speed (derivative_cutoff_hz) and lets the speed open the pose's cutoff:
//
//   translation: v = (x - x_hat) / dt,  v_hat <- v_hat + alpha(f_d) (v - v_hat),
//                f_c = min_cutoff_hz + translation_beta |v_hat|,
//                x_hat <- x_hat + alpha(f_c) (x - x_hat);
//   rotation:    w = log(q_hat^-1 q) / dt (rotation vector per second), w_hat likewise,
//                f_c = min_cutoff_hz + rotation_beta |w_hat|,
//                q_hat <- slerp(q_hat, q, alpha(f_c)).
//
// Still, the pose is averaged over about 1 / (2 pi min_cutoff_hz) s; moving, the cutoff rises with
// the speed and the lag falls. Causal (one frame in, one out), so it runs in real time. The
// tracker's own state (motion model, prediction, checks) keeps the unfiltered poses; only what it
// reports is filtered. A detection (a new start) or a loss restarts the filter at the next pose.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "core/rigid3.h"

namespace mmh::track {

struct PoseFilterOptions {
  // Off by default: the reported pose is the frame's own estimate.
  bool enabled = false;
  double min_cutoff_hz = 1.0;         // f_min: the cutoff when still [Hz]
  double translation_beta = 20.0;     // cutoff added per m/s of smoothed speed [Hz s/m]
  double rotation_beta = 1.0;         // cutoff added per rad/s of smoothed angular speed [Hz s]
  double derivative_cutoff_hz = 1.0;  // f_d: the speeds' own low-pass [Hz]

  template <class V>
  void VisitFields(V& v) {
    v("enabled", enabled);
    v("min_cutoff_hz", min_cutoff_hz);
    v("translation_beta", translation_beta);
    v("rotation_beta", rotation_beta);
    v("derivative_cutoff_hz", derivative_cutoff_hz);
  }
  // Positive finite cutoffs, non-negative finite betas (InputError naming the key).
  void Validate(const std::string& prefix) const;
};

class PoseFilter {
 public:
  explicit PoseFilter(const PoseFilterOptions& options);

  // The filtered pose for a measured `camera_T_proxy` at `timestamp` [s]. The first pose after
  // construction or Reset(), or one whose timestamp does not advance, is returned as it is (and
  // restarts the filter there).
  Rigid3 Filter(double timestamp, const Rigid3& camera_T_proxy);
  // Forgets the state: the next pose starts the filter.
  void Reset();

 private:
  PoseFilterOptions options_;
  std::optional<double> last_time_;
  Rigid3 pose_;                                         // x_hat, q_hat
  Eigen::Vector3d velocity_ = Eigen::Vector3d::Zero();  // v_hat [m/s]
  Eigen::Vector3d angular_ = Eigen::Vector3d::Zero();   // w_hat [rad/s], in the filtered frame
};

}  // namespace mmh::track
