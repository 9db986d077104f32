#include "track/trajectory_smoother.h"

#include <Eigen/Geometry>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace mmh::track {

void TrajectorySmootherOptions::Validate(const std::string& prefix) const {
  if (degree < 1 || degree > 2) {
    ThrowBadValue(prefix + ".degree", std::to_string(degree), "1 (line) or 2 (parabola)");
  }
  if (half_window < degree + 1 || half_window > 60) {
    ThrowBadValue(prefix + ".half_window", std::to_string(half_window),
                  "an integer from degree + 1 = " + std::to_string(degree + 1) +
                      " (every fit keeps a spare frame) to 60 [frames]");
  }
  RequirePositive(break_rotation_deg, prefix + ".break_rotation_deg");
  RequirePositive(break_translation, prefix + ".break_translation");
}

namespace {

// The rotation vector of `rotation` [rad] (its logarithm).
Eigen::Vector3d Log(const Eigen::Quaterniond& rotation) {
  const Eigen::AngleAxisd angle_axis(rotation);
  return angle_axis.angle() * angle_axis.axis();
}

Eigen::Quaterniond Exp(const Eigen::Vector3d& vector) {
  const double angle = vector.norm();
  if (angle < 1e-300) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, vector / angle));
}

// Whether `pose` at time t continues the run whose last two poses are `before` (at t_before) and
// `last` (at t_last); without `before`, whether it stays near `last`.
bool Continues(const Rigid3* before, double t_before, const Rigid3& last, double t_last,
               const Rigid3& pose, double t, const TrajectorySmootherOptions& options) {
  if (!(t > t_last)) return false;
  Rigid3 predicted = last;
  if (before) {
    // Constant velocity, rotation in the camera frame: last = Exp(w dt) before.
    const double ratio = (t - t_last) / (t_last - t_before);
    predicted.rotation =
        Exp(ratio * Log(last.rotation * before->rotation.inverse())) * last.rotation;
    predicted.translation = last.translation + ratio * (last.translation - before->translation);
  }
  return RotationAngle(pose.rotation, predicted.rotation) * 180 / M_PI <=
             options.break_rotation_deg &&
         (pose.translation - predicted.translation).norm() <= options.break_translation;
}

}  // namespace

TrajectorySmootherSummary SmoothTrajectory(const std::vector<double>& timestamps,
                                           const std::vector<bool>& measured,
                                           const TrajectorySmootherOptions& options,
                                           std::vector<Rigid3>* poses) {
  options.Validate("smoothing");
  const size_t frames = poses->size();
  if (timestamps.size() != frames || measured.size() != frames) {
    throw InputError("trajectory smoothing: " + std::to_string(frames) + " poses, " +
                     std::to_string(timestamps.size()) + " timestamps and " +
                     std::to_string(measured.size()) +
                     " measured flags (expected one of each per frame)");
  }
  TrajectorySmootherSummary summary;
  if (!options.enabled) return summary;

  // Runs of measured frames [first, last], split where a frame is not measured or a pose jumps.
  std::vector<std::pair<size_t, size_t>> runs;
  const std::vector<Rigid3>& in = *poses;
  for (size_t i = 0; i < frames; ++i) {
    if (!measured[i]) continue;
    bool continues = false;
    if (!runs.empty() && runs.back().second + 1 == i) {
      const size_t first = runs.back().first;
      const Rigid3* before = i >= first + 2 ? &in[i - 2] : nullptr;
      continues = Continues(before, before ? timestamps[i - 2] : 0.0, in[i - 1], timestamps[i - 1],
                            in[i], timestamps[i], options);
      summary.breaks += !continues;
    }
    if (continues) {
      runs.back().second = i;
    } else {
      runs.emplace_back(i, i);
    }
  }
  summary.runs = static_cast<int>(runs.size());

  // Savitzky–Golay: per frame, least squares of a polynomial in (t_j - t_i) to the window's
  // rotation vectors Log(R_j R_i^-1) and translations t_j - t_i; the smoothed pose is the fit's
  // value at t_i (its constant coefficient). Rows: the window's frames; columns 0..degree: the
  // powers of the normalised time (for conditioning); right-hand side #window by 6.
  std::vector<Rigid3> out = in;
  const int h = options.half_window;
  const int columns = options.degree + 1;
  for (const auto& [first, last] : runs) {
    if (last - first + 1 < static_cast<size_t>(options.degree + 2)) continue;
    for (size_t i = first; i <= last; ++i) {
      const size_t lo = i >= first + h ? i - h : first;
      const size_t hi = std::min(last, i + h);
      const int n = static_cast<int>(hi - lo + 1);
      const double scale = std::max(timestamps[hi] - timestamps[i], timestamps[i] - timestamps[lo]);
      Eigen::MatrixXd design(n, columns);
      Eigen::MatrixXd values(n, 6);
      const Eigen::Quaterniond inverse = in[i].rotation.inverse();
      for (int r = 0; r < n; ++r) {
        const size_t j = lo + r;
        const double tau = (timestamps[j] - timestamps[i]) / scale;
        double power = 1.0;
        for (int c = 0; c < columns; ++c, power *= tau) design(r, c) = power;
        values.block<1, 3>(r, 0) = Log(in[j].rotation * inverse).transpose();
        values.block<1, 3>(r, 3) = (in[j].translation - in[i].translation).transpose();
      }
      const Eigen::MatrixXd fit = design.colPivHouseholderQr().solve(values);
      out[i].rotation = (Exp(fit.block<1, 3>(0, 0).transpose()) * in[i].rotation).normalized();
      out[i].translation = in[i].translation + fit.block<1, 3>(0, 3).transpose();
      ++summary.measured;
      summary.mean_change_deg += RotationAngle(out[i].rotation, in[i].rotation) * 180 / M_PI;
      summary.mean_change += (out[i].translation - in[i].translation).norm();
    }
  }
  if (summary.measured > 0) {
    summary.mean_change_deg /= summary.measured;
    summary.mean_change /= summary.measured;
  }
  *poses = std::move(out);
  return summary;
}

}  // namespace mmh::track
