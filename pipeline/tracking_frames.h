// The per-frame table of tracked takes against their ground truth: for every frame, how the true
// pose was seen and moved, what the tracker reported and how far off it was, and what the slider
// reader read. It is what the fast mode's error model is measured on (EstimateErrorModel in
// pipeline/error_model.h): a full-fidelity study writes it as tracking_errors.csv, so that the
// model can be refitted (`mmh error-model --frames FILE`) and its errors plotted without running
// the study again.
#pragma once

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "core/annotation.h"
#include "core/trajectory.h"
#include "core/rigid3.h"
#include "track/track_status.h"

namespace mmh::pipeline {

// One tracked take against its ground truth (all #frames).
struct TrackingObservation {
  const Trajectory* truth = nullptr;    // table_T_proxy
  const Trajectory* tracked = nullptr;  // table_T_proxy as reported
  const std::vector<track::TrackStatus>* status = nullptr;
  Eigen::Vector3d table_camera_position = Eigen::Vector3d::Zero();  // the camera's centre
};

// One slider reading against the block's true values (all #frames).
struct ReadingObservation {
  const Annotation* truth = nullptr;
  const Annotation* read = nullptr;
  const std::vector<bool>* found = nullptr;
};

// How a true pose table_T_proxy is seen from a camera at `table_camera_position` (table frame):
// the tilt of the proxy's z axis from the table's vertical [deg, 0..180], and its heading φ
// [deg, 0..360): the angle in the table plane from the direction proxy → camera to the proxy's
// x axis, counter-clockwise seen from above (0: facing the camera).
double ProxyTiltDeg(const Rigid3& table_T_proxy);
double ProxyHeadingDeg(const Rigid3& table_T_proxy, const Eigen::Vector3d& table_camera_position);

// The error of `tracked` against `truth` in the proxy frame: rotation vector [rad] and
// translation [m], proxy_T_error = truth⁻¹ · tracked = (Exp(r), e).
std::array<double, 6> PoseError(const Rigid3& truth, const Rigid3& tracked);

struct TrackingFrame {
  double time = 0.0;  // s, the truth's timestamp
  track::TrackStatus status = track::TrackStatus::kTracked;
  // The true pose as seen (ProxyHeadingDeg, ProxyTiltDeg) and its speed: translation [m/s] and
  // turn [rad/s] from this frame to the next (from the previous one at the last frame; 0 for a
  // one-frame take).
  double heading_deg = 0.0;
  double tilt_deg = 0.0;
  double speed = 0.0;
  double turn_rate = 0.0;
  // PoseError(truth, tracked); zero where the frame is lost.
  std::array<double, 6> error{};
  // The slider, where the take was annotated (has_slider): true and read values, and whether the
  // block was found (read holds the last found value where not).
  bool has_slider = false;
  double slider_truth = 0.0;
  double slider_read = 0.0;
  bool slider_found = false;
};

struct TakeFrames {
  std::string animator;  // "A01", ...
  int take = 0;          // 0-based
  std::vector<TrackingFrame> frames;
};

// The frames of one take. `reading` may be null (not annotated). Throws InputError when the
// lengths differ or data are missing, naming the take ("tracking observation <take>" where
// `animator` is empty).
TakeFrames MeasureTakeFrames(const std::string& animator, int take,
                             const TrackingObservation& tracking,
                             const ReadingObservation* reading);

struct TakeRun;  // pipeline/animator_run.h

// The frames of every take of one animator's run at full fidelity (the takes' true camera pose
// places the camera; in fast fidelity it is the identity and the table would be meaningless).
// Takes without a slider reading (truth_annotation empty) have no slider columns. Used by the
// study (tracking_errors.csv of all animators) and `mmh run` (its own tracking_errors.csv).
std::vector<TakeFrames> MeasureRunFrames(const std::string& animator,
                                         const std::vector<TakeRun>& takes);

// The table as CSV, one row per frame, columns
//   animator,take,frame,time_s,status,heading_deg,tilt_deg,speed_m_s,turn_rate_rad_s,
//   error_rx_rad,error_ry_rad,error_rz_rad,error_tx_m,error_ty_m,error_tz_m,
//   slider_truth,slider_read,slider_found
// numbers in the shortest form that reads back to the same double (so a refit from the file gives
// the bytes of the fit in the study); the error columns are empty where the frame is lost, the
// slider columns where the take has no reading.
std::string TakeFramesCsv(const std::vector<TakeFrames>& takes);

// Reads TakeFramesCsv's format back. A take is a run of rows with the same animator and take,
// frames 0, 1, ... in order. Throws InputError naming the file, line and column for anything else.
std::vector<TakeFrames> ReadTakeFramesCsv(const std::filesystem::path& path);

}  // namespace mmh::pipeline
