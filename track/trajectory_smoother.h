// Offline smoothing of a recorded take's measured poses: each measured pose is replaced by a local
// polynomial fit (Savitzky and Golay 1964) to the measured poses around it, rotations in the
// tangent space of the pose being smoothed. A take is recorded first and composited afterwards,
// so the whole trajectory is known: the fit is centred (no lag), unlike the tracker's causal
// motion prior. It removes the frame-to-frame noise of the depth data (the Kinect's noise is
// independent from frame to frame; on Soldier story takes the error about the table's horizontal
// axes has a lag-1 autocorrelation of 0.2–0.4) and keeps motion up to the fit's degree exactly.
#pragma once

#include <string>
#include <vector>

#include "core/rigid3.h"

namespace mmh::track {

struct TrajectorySmootherOptions {
  // false: the measured poses are the trajectory.
  bool enabled = true;
  // The fit uses the measured frames of the same run within half_window frames of the frame
  // smoothed [frames]; 4 at 30 Hz spans 0.3 s.
  int half_window = 4;
  // Degree of the local polynomial in time: 1 (local line) or 2 (local parabola: keeps constant
  // angular and linear acceleration exactly; less smoothing than a line for the same window).
  int degree = 2;
  // A run of measured frames ends where a pose leaves the constant-velocity extrapolation of the
  // two before it (the pose before it, at a run's second frame) by more than break_rotation_deg
  // [deg] or break_translation [m]: a switch between twins, a recovered slide, a re-detection.
  // Smoothing across it would smear the jump over the window. The defaults are about four times
  // the extrapolation's noise on story takes (1.5 deg, 2.5 mm).
  double break_rotation_deg = 6.0;
  double break_translation = 0.012;

  template <class V>
  void VisitFields(V& v) {
    v("enabled", enabled);
    v("half_window", half_window);
    v("degree", degree);
    v("break_rotation_deg", break_rotation_deg);
    v("break_translation", break_translation);
  }
  void Validate(const std::string& prefix) const;
};

struct TrajectorySmootherSummary {
  int measured = 0;  // frames smoothed (measured, in a run of at least degree + 2 frames)
  int runs = 0;      // runs of measured frames
  int breaks = 0;    // runs ended by a jump (the others by a frame not measured)
  double mean_change_deg = 0.0;  // mean rotation change of the smoothed frames [deg]
  double mean_change = 0.0;      // mean translation change [m]
};

// Smooths `poses` in place. `timestamps`, `poses` and `measured` have one entry per frame
// (#frames); only frames with `measured` true are fitted and changed (predicted and lost frames are
// neither used nor changed, and they end a run). A run shorter than degree + 2 frames is left as
// measured. Throws InputError on mismatched lengths or timestamps not increasing within a run.
TrajectorySmootherSummary SmoothTrajectory(const std::vector<double>& timestamps,
                                           const std::vector<bool>& measured,
                                           const TrajectorySmootherOptions& options,
                                           std::vector<Rigid3>* poses);

}  // namespace mmh::track
