#include "pipeline/run_output.h"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <sstream>

#include "core/annotation.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_text.h"
#include "core/text_parsing.h"
#include "core/tum_io.h"
#include "metrics/tracking_metrics.h"
#include "pipeline/run_metrics.h"
#include "pipeline/tracking_frames.h"

namespace mmh::pipeline {

namespace {

std::filesystem::path TakeFolder(const std::filesystem::path& out, const TakeRun& take,
                                 bool practice) {
  return practice ? out / "practice" : out / "takes" / ("take_" + std::to_string(take.take));
}

void WriteMontage(const std::filesystem::path& dir, const montage::Montage& m,
                  const std::string& what) {
  EnsureDirectory(dir);
  WriteTum(dir / "montage.tum", m.trajectory,
           "MotionMontage montage from " + what + " (mmh run)\ntimestamp tx ty tz qx qy qz qw");
  WriteFileAtomically(dir / "segments.csv", montage::SegmentsToCsv(m.segments));
  WriteFileAtomically(dir / "timeline.csv", montage::TimelineToCsv(m));
  // Without the compositor's timings: the same config and seed give the same bytes (the run's
  // timings are in run.json).
  nlohmann::json summary = montage::SummaryToJson(m.summary, m.segments);
  summary.erase("seconds");
  WriteFileAtomically(dir / "summary.json", summary.dump(2) + "\n");
}

nlohmann::json PoseToJson(const Rigid3& pose) {
  return {{"translation", {pose.translation.x(), pose.translation.y(), pose.translation.z()}},
          {"quaternion_xyzw",
           {pose.rotation.x(), pose.rotation.y(), pose.rotation.z(), pose.rotation.w()}}};
}

Rigid3 PoseFromJson(const nlohmann::json& j) {
  const auto& t = j.at("translation");
  const auto& q = j.at("quaternion_xyzw");
  return Rigid3(
      Eigen::Quaterniond(q.at(3).get<double>(), q.at(0).get<double>(), q.at(1).get<double>(),
                         q.at(2).get<double>()),
      Eigen::Vector3d(t.at(0).get<double>(), t.at(1).get<double>(), t.at(2).get<double>()));
}

}  // namespace

void WriteTakeRun(const std::filesystem::path& out, const TakeRun& take, bool practice) {
  const std::filesystem::path dir = TakeFolder(out, take, practice);
  EnsureDirectory(dir);
  WriteTum(dir / "truth.tum", take.truth,
           "ground truth table_T_proxy\ntimestamp tx ty tz qx qy qz qw");
  if (!take.tracked.poses.empty()) {
    WriteTum(dir / "tracked.tum", take.tracked,
             "tracked table_T_proxy (lost frames interpolated; see status.csv)\n"
             "timestamp tx ty tz qx qy qz qw");
  }
  const bool annotated = !take.slider_found.empty();
  std::ostringstream status;
  status << "frame,timestamp,status" << (annotated ? ",slider_found" : "") << '\n';
  for (size_t i = 0; i < take.status.size(); ++i) {
    status << i << ',' << FormatNumber(take.truth.timestamps[i]) << ','
           << track::TrackStatusName(take.status[i]);
    if (annotated) status << ',' << (take.slider_found[i] ? 1 : 0);
    status << '\n';
  }
  WriteFileAtomically(dir / "status.csv", status.str());
  if (!take.truth_annotation.values.empty()) {
    WriteAnnotationCsv(dir / "truth_annotation.csv", take.truth_annotation);
  }
  if (!take.read_annotation.values.empty()) {
    WriteAnnotationCsv(dir / "read_annotation.csv", take.read_annotation);
  }
  std::ostringstream quality;
  quality << "frame,timestamp,beat,quality" << (practice ? "" : ",judgement") << '\n';
  for (size_t i = 0; i < take.truth.poses.size(); ++i) {
    quality << i << ',' << FormatNumber(take.truth.timestamps[i]) << ','
            << take.performed.script_beat[i] << ','
            << FormatNumber(take.performed.quality.quality[i]);
    if (!practice) quality << ',' << FormatNumber(take.annotation.judgement[i]);
    quality << '\n';
  }
  WriteFileAtomically(dir / "quality.csv", quality.str());
  // Last: its presence marks the take's folder complete (mmh run --resume).
  const nlohmann::json session = {
      {"frames", static_cast<int>(take.truth.poses.size())},
      {"camera_T_table", PoseToJson(take.camera_T_table)},
      {"estimated_camera_T_table", PoseToJson(take.estimated_camera_T_table)}};
  WriteFileAtomically(dir / "session.json", session.dump(2) + "\n");
}

bool LoadTakeRun(const std::filesystem::path& out, TakeRun& take, bool practice) {
  const std::filesystem::path dir = TakeFolder(out, take, practice);
  const bool annotated = !practice;
  if (!std::filesystem::exists(dir / "session.json")) return false;
  const int frames = static_cast<int>(take.truth.poses.size());
  auto inconsistent = [&](const std::filesystem::path& file, const std::string& value,
                          const std::string& expected) {
    ThrowBadValue((dir / file).string(), value,
                  expected +
                      " (stage outputs inconsistent with this run: run without --resume "
                      "or into a new folder)");
  };
  nlohmann::json session;
  try {
    session = ReadJsonFile(dir / "session.json");
  } catch (const InputError&) {
    inconsistent("session.json", "unreadable", "the session summary mmh run writes");
  }
  if (!session.is_object() || !session.contains("frames")) {
    inconsistent("session.json", "unreadable", "the session summary mmh run writes");
  }
  if (session["frames"] != frames) {
    inconsistent("session.json", session["frames"].dump() + " frames",
                 std::to_string(frames) + " frames of the performed take");
  }
  for (const char* file : {"truth.tum", "tracked.tum", "status.csv"}) {
    if (!std::filesystem::exists(dir / file)) inconsistent(file, "missing", "the file");
  }
  const Trajectory truth = ReadTum(dir / "truth.tum");
  if (static_cast<int>(truth.poses.size()) != frames) {
    inconsistent("truth.tum", std::to_string(truth.poses.size()) + " poses",
                 std::to_string(frames) + " (the performed take's frames)");
  }
  for (int i = 0; i < frames; ++i) {
    if ((truth.poses[i].translation - take.truth.poses[i].translation).norm() > 1e-6) {
      inconsistent("truth.tum", "frame " + std::to_string(i) + " elsewhere",
                   "the performed take's pose (another participant, take or config?)");
    }
  }
  take.tracked = ReadTum(dir / "tracked.tum");
  if (static_cast<int>(take.tracked.poses.size()) != frames) {
    inconsistent("tracked.tum", std::to_string(take.tracked.poses.size()) + " poses",
                 std::to_string(frames) + " (one per frame)");
  }
  take.status.clear();
  take.slider_found.clear();
  int row = 0;
  const std::string text = ReadTextFile(dir / "status.csv");
  std::istringstream lines(text);
  std::string line;
  std::getline(lines, line);  // header
  while (std::getline(lines, line)) {
    const auto fields = SplitCsvFields(Trim(line));
    const std::string where = "status.csv line " + std::to_string(row + 2);
    if (fields.size() != (annotated ? 4u : 3u)) {
      inconsistent(where, "\"" + line + "\"",
                   annotated ? "frame,timestamp,status,slider_found" : "frame,timestamp,status");
    }
    const std::optional<track::TrackStatus> status = track::TrackStatusFromName(fields[2]);
    if (!status) {
      inconsistent(where, "\"" + std::string(fields[2]) + "\"", "tracked, predicted or lost");
    }
    take.status.push_back(*status);
    if (annotated) take.slider_found.push_back(fields[3] == "1");
    ++row;
  }
  if (row != frames) {
    inconsistent("status.csv", std::to_string(row) + " rows", std::to_string(frames) + " frames");
  }
  if (annotated) {
    if (!std::filesystem::exists(dir / "read_annotation.csv")) {
      inconsistent("read_annotation.csv", "missing", "the file");
    }
    take.read_annotation = ReadAnnotationCsv(dir / "read_annotation.csv");
    if (static_cast<int>(take.read_annotation.values.size()) != frames) {
      inconsistent("read_annotation.csv",
                   std::to_string(take.read_annotation.values.size()) + " values",
                   std::to_string(frames) + " (one per frame)");
    }
  }
  take.camera_T_table = PoseFromJson(session["camera_T_table"]);
  take.estimated_camera_T_table = PoseFromJson(session["estimated_camera_T_table"]);
  return true;
}

std::string MetricsToCsv(const nlohmann::json& metrics) {
  std::ostringstream csv;
  csv << "scope,take,metric,value\n";
  for (const auto& [key, value] : FlattenMetrics(metrics)) {
    const size_t dot = key.find('.');
    const std::string scope = key.substr(0, dot);
    std::string rest = dot == std::string::npos ? "" : key.substr(dot + 1);
    std::string take;
    if (scope == "takes") {
      const size_t next = rest.find('.');
      take = rest.substr(0, next);
      rest = next == std::string::npos ? "" : rest.substr(next + 1);
    }
    if (rest.find("seam_list") != std::string::npos ||
        rest.find("failures.") != std::string::npos) {
      continue;  // per-event lists: seams.csv and tracking_frames.csv
    }
    csv << scope << ',' << take << ',' << rest << ',' << FormatNumber(value) << '\n';
  }
  return csv.str();
}

void WriteAnimatorRun(const std::filesystem::path& out, const AnimatorRun& run,
                      bool full_fidelity) {
  EnsureDirectory(out);
  WriteMontage(out / "montage", run.montage, "the tracked takes and read annotations");
  WriteMontage(out / "montage_truth", run.truth_montage, "the ground truth");
  const nlohmann::json metrics = ToJson(*run.metrics);
  WriteFileAtomically(out / "metrics.json", metrics.dump(2) + "\n");
  WriteFileAtomically(out / "metrics.csv", MetricsToCsv(metrics));

  std::ostringstream seams;
  seams << "montage,seam,frame,from_take,to_take,position_jump_m,velocity_jump_m_per_s,"
           "angular_velocity_jump_deg_per_s\n";
  for (const auto& [which, montage] : {std::pair{"tracked", &run.metrics->tracked},
                                        std::pair{"truth", &run.metrics->truth}}) {
    int k = 0;
    for (const SeamJump& s : montage->seam_list) {
      seams << which << ',' << k++ << ',' << s.frame << ',' << s.from_take << ',' << s.to_take
            << ',' << FormatNumber(s.position_jump_m) << ','
            << FormatNumber(s.velocity_jump_m_per_s) << ','
            << FormatNumber(s.angular_velocity_jump_deg_per_s) << '\n';
    }
  }
  WriteFileAtomically(out / "seams.csv", seams.str());

  // Per-frame tracking errors in the table frame (empty fields where lost).
  std::ostringstream frames;
  frames << "take,frame,status,rotation_deg,translation_m\n";
  for (const TakeRun& take : run.takes) {
    for (size_t i = 0; i < take.status.size(); ++i) {
      frames << take.take << ',' << i << ',' << track::TrackStatusName(take.status[i]) << ',';
      if (take.status[i] != track::TrackStatus::kLost) {
        const Rigid3& a = take.tracked.poses[i];
        const Rigid3& b = take.truth.poses[i];
        frames << FormatNumber(RotationAngle(a.rotation, b.rotation) * 180.0 /
                               3.14159265358979323846)
               << ',' << FormatNumber((a.translation - b.translation).norm());
      } else {
        frames << ',';
      }
      frames << '\n';
    }
  }
  WriteFileAtomically(out / "tracking_frames.csv", frames.str());

  // Full fidelity: every tracked frame against its truth, in the study's format, for refitting
  // the fast mode's error model from a run (`mmh error-model --frames`). Fast fidelity draws its
  // errors from that model and has no camera: nothing to measure.
  if (full_fidelity) {
    char animator[16];
    std::snprintf(animator, sizeof(animator), "A%02d", run.participant.index + 1);
    WriteFileAtomically(out / "tracking_errors.csv",
                        TakeFramesCsv(MeasureRunFrames(animator, run.takes)));
  }
}

}  // namespace mmh::pipeline
