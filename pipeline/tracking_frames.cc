#include "pipeline/tracking_frames.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <optional>
#include <string_view>

#include "core/error.h"
#include "core/text_parsing.h"
#include "pipeline/animator_run.h"

namespace mmh::pipeline {
namespace {

constexpr double kPi = 3.14159265358979323846;

constexpr const char* kHeader =
    "animator,take,frame,time_s,status,heading_deg,tilt_deg,speed_m_s,turn_rate_rad_s,"
    "error_rx_rad,error_ry_rad,error_rz_rad,error_tx_m,error_ty_m,error_tz_m,"
    "slider_truth,slider_read,slider_found";
constexpr std::size_t kColumns = 18;

// The rotation angle [rad] between two orientations.
double TurnAngle(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  Eigen::Quaterniond q = a.conjugate() * b;
  return 2.0 * std::atan2(q.vec().norm(), std::abs(q.w()));
}

}  // namespace

double ProxyTiltDeg(const Rigid3& table_T_proxy) {
  const Eigen::Matrix3d rotation = table_T_proxy.rotation.toRotationMatrix();
  return std::acos(std::clamp(rotation(2, 2), -1.0, 1.0)) * 180.0 / kPi;
}

double ProxyHeadingDeg(const Rigid3& table_T_proxy, const Eigen::Vector3d& table_camera_position) {
  // The proxy's x axis and the direction to the camera, both in the table plane.
  const Eigen::Vector3d facing = table_T_proxy.rotation.toRotationMatrix().col(0);
  const Eigen::Vector3d to_camera = table_camera_position - table_T_proxy.translation;
  const double phi = std::atan2(facing.y(), facing.x()) - std::atan2(to_camera.y(), to_camera.x());
  double degrees = std::fmod(phi * 180.0 / kPi, 360.0);
  if (degrees < 0) degrees += 360.0;
  return degrees;
}

std::array<double, 6> PoseError(const Rigid3& truth, const Rigid3& tracked) {
  Eigen::Quaterniond q = truth.rotation.conjugate() * tracked.rotation;
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const Eigen::AngleAxisd angle_axis(q.normalized());
  const Eigen::Vector3d r = angle_axis.angle() * angle_axis.axis();
  const Eigen::Vector3d e = truth.rotation.conjugate() * (tracked.translation - truth.translation);
  return {r.x(), r.y(), r.z(), e.x(), e.y(), e.z()};
}

TakeFrames MeasureTakeFrames(const std::string& animator, int take,
                             const TrackingObservation& obs, const ReadingObservation* reading) {
  const std::string name = animator.empty()
                               ? "tracking observation " + std::to_string(take)
                               : "animator " + animator + ", take " + std::to_string(take);
  if (!obs.truth || !obs.tracked || !obs.status) throw InputError(name + ": missing tracking data");
  const std::size_t n = obs.truth->size();
  if (obs.tracked->size() != n || obs.status->size() != n) {
    throw InputError(name + ": truth, tracked and status lengths differ (" + std::to_string(n) +
                     ", " + std::to_string(obs.tracked->size()) + ", " +
                     std::to_string(obs.status->size()) + ")");
  }
  const bool slider = reading != nullptr;
  if (slider) {
    if (!reading->truth || !reading->read || !reading->found) {
      throw InputError(name + ": missing slider data");
    }
    if (reading->truth->size() != n || reading->read->size() != n ||
        reading->found->size() != n) {
      throw InputError(name + ": slider truth, read and found lengths (" +
                       std::to_string(reading->truth->size()) + ", " +
                       std::to_string(reading->read->size()) + ", " +
                       std::to_string(reading->found->size()) + ") differ from the take's " +
                       std::to_string(n) + " frames");
    }
  }
  TakeFrames out{animator, take, std::vector<TrackingFrame>(n)};
  const auto& poses = obs.truth->poses;
  const auto& times = obs.truth->timestamps;
  for (std::size_t t = 0; t < n; ++t) {
    TrackingFrame& f = out.frames[t];
    f.time = t < times.size() ? times[t] : 0.0;
    f.status = (*obs.status)[t];
    f.heading_deg = ProxyHeadingDeg(poses[t], obs.table_camera_position);
    f.tilt_deg = ProxyTiltDeg(poses[t]);
    if (n > 1 && times.size() == n) {
      const std::size_t a = t + 1 < n ? t : t - 1;
      const double dt = times[a + 1] - times[a];
      if (dt > 0) {
        f.speed = (poses[a + 1].translation - poses[a].translation).norm() / dt;
        f.turn_rate = TurnAngle(poses[a].rotation, poses[a + 1].rotation) / dt;
      }
    }
    if (f.status != track::TrackStatus::kLost) f.error = PoseError(poses[t], obs.tracked->poses[t]);
    if (slider) {
      f.has_slider = true;
      f.slider_truth = reading->truth->values[t];
      f.slider_read = reading->read->values[t];
      f.slider_found = (*reading->found)[t];
    }
  }
  return out;
}

std::string TakeFramesCsv(const std::vector<TakeFrames>& takes) {
  std::string out = std::string(kHeader) + "\n";
  for (const TakeFrames& take : takes) {
    for (std::size_t t = 0; t < take.frames.size(); ++t) {
      const TrackingFrame& f = take.frames[t];
      out += take.animator + "," + std::to_string(take.take) + "," + std::to_string(t) + "," +
             FormatNumber(f.time) + "," + track::TrackStatusName(f.status) + "," +
             FormatNumber(f.heading_deg) + "," + FormatNumber(f.tilt_deg) + "," +
             FormatNumber(f.speed) + "," + FormatNumber(f.turn_rate);
      const bool lost = f.status == track::TrackStatus::kLost;
      for (double e : f.error) out += "," + (lost ? std::string() : FormatNumber(e));
      if (f.has_slider) {
        out += "," + FormatNumber(f.slider_truth) + "," + FormatNumber(f.slider_read) + "," +
               (f.slider_found ? "1" : "0");
      } else {
        out += ",,,";
      }
      out += "\n";
    }
  }
  return out;
}

std::vector<TakeFrames> ReadTakeFramesCsv(const std::filesystem::path& path) {
  const std::string text = ReadTextFile(path);
  std::vector<TakeFrames> takes;
  std::size_t start = 0;
  int line = 0;
  bool header_seen = false;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string_view row = Trim(std::string_view(text).substr(start, end - start));
    start = end + 1;
    ++line;
    const std::string where = path.string() + ":" + std::to_string(line);
    if (row.empty()) continue;
    if (!header_seen) {
      if (row != kHeader) {
        throw InputError(where + ": the header is '" + std::string(row.substr(0, 200)) +
                         "', expected '" + kHeader + "' (a study's tracking_errors.csv)");
      }
      header_seen = true;
      continue;
    }
    const std::vector<std::string_view> fields = SplitCsvFields(row);
    if (fields.size() != kColumns) {
      throw InputError(where + ": " + std::to_string(fields.size()) + " fields, expected " +
                       std::to_string(kColumns) + " (" + kHeader + ")");
    }
    static constexpr const char* kNames[kColumns] = {
        "animator",     "take",         "frame",        "time_s",       "status",
        "heading_deg",  "tilt_deg",     "speed_m_s",    "turn_rate_rad_s", "error_rx_rad",
        "error_ry_rad", "error_rz_rad", "error_tx_m",   "error_ty_m",   "error_tz_m",
        "slider_truth", "slider_read",  "slider_found"};
    const auto bad = [&](std::size_t column, const std::string& expected) {
      throw InputError(where + ": column " + kNames[column] + " is '" +
                       std::string(fields[column]) + "', expected " + expected);
    };
    const auto number = [&](std::size_t column) {
      double value = 0.0;
      if (!ParseDouble(fields[column], &value) || !std::isfinite(value)) {
        bad(column, "a finite number");
      }
      return value;
    };
    const auto whole = [&](std::size_t column) {
      int value = -1;
      const std::string_view s = fields[column];
      const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
      if (ec != std::errc() || ptr != s.data() + s.size() || value < 0) {
        bad(column, "a whole number >= 0");
      }
      return value;
    };
    const std::string animator(fields[0]);
    if (animator.empty()) bad(0, "an animator id");
    const int take = whole(1);
    const int frame = whole(2);
    if (takes.empty() || takes.back().animator != animator || takes.back().take != take) {
      takes.push_back({animator, take, {}});
    }
    TakeFrames& current = takes.back();
    if (frame != static_cast<int>(current.frames.size())) {
      bad(2, std::to_string(current.frames.size()) + " (the take's frames in order from 0)");
    }
    TrackingFrame f;
    f.time = number(3);
    const std::optional<track::TrackStatus> status = track::TrackStatusFromName(fields[4]);
    if (!status) bad(4, "tracked, predicted or lost");
    f.status = *status;
    f.heading_deg = number(5);
    f.tilt_deg = number(6);
    f.speed = number(7);
    f.turn_rate = number(8);
    const bool lost = f.status == track::TrackStatus::kLost;
    for (std::size_t k = 0; k < 6; ++k) {
      if (lost) {
        if (!fields[9 + k].empty()) bad(9 + k, "empty (the frame is lost)");
      } else {
        f.error[k] = number(9 + k);
      }
    }
    const bool slider = !fields[15].empty() || !fields[16].empty() || !fields[17].empty();
    if (slider) {
      f.has_slider = true;
      f.slider_truth = number(15);
      f.slider_read = number(16);
      if (fields[17] != "0" && fields[17] != "1") bad(17, "0 or 1");
      f.slider_found = fields[17] == "1";
    }
    if (!current.frames.empty() && current.frames.front().has_slider != f.has_slider) {
      bad(15, "slider values in every frame of the take or in none");
    }
    current.frames.push_back(f);
  }
  if (!header_seen) throw InputError(path.string() + ": empty, expected the header '" + kHeader + "'");
  return takes;
}

std::vector<TakeFrames> MeasureRunFrames(const std::string& animator,
                                         const std::vector<TakeRun>& takes) {
  std::vector<TakeFrames> frames;
  frames.reserve(takes.size());
  for (const TakeRun& take : takes) {
    const TrackingObservation tracking{&take.truth, &take.tracked, &take.status,
                                       take.camera_T_table.Inverse().translation};
    const ReadingObservation reading{&take.truth_annotation, &take.read_annotation,
                                     &take.slider_found};
    frames.push_back(MeasureTakeFrames(animator, take.take, tracking,
                                       take.truth_annotation.values.empty() ? nullptr : &reading));
  }
  return frames;
}

}  // namespace mmh::pipeline
