#include "pipeline/run_output.h"

#include <sstream>

#include "core/annotation.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/tum_io.h"
#include "metrics/tracking_metrics.h"
#include "pipeline/run_metrics.h"

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
  std::ostringstream status;
  status << "frame,timestamp,status\n";
  for (size_t i = 0; i < take.status.size(); ++i) {
    status << i << ',' << FormatNumber(take.truth.timestamps[i]) << ','
           << track::TrackStatusName(take.status[i]) << '\n';
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

void WriteAnimatorRun(const std::filesystem::path& out, const AnimatorRun& run) {
  EnsureDirectory(out);
  WriteMontage(out / "montage", run.montage, "the tracked takes and read annotations");
  WriteMontage(out / "montage_truth", run.truth_montage, "the ground truth");
  WriteFileAtomically(out / "metrics.json", run.metrics.dump(2) + "\n");
  WriteFileAtomically(out / "metrics.csv", MetricsToCsv(run.metrics));

  std::ostringstream seams;
  seams << "montage,seam,frame,from_take,to_take,position_jump_m,velocity_jump_m_per_s,"
           "angular_velocity_jump_deg_per_s\n";
  for (const char* which : {"tracked", "truth"}) {
    int k = 0;
    for (const nlohmann::json& s : run.metrics["montage"][which]["seam_list"]) {
      seams << which << ',' << k++ << ',' << s["frame"].get<int>() << ','
            << s["from_take"].get<int>() << ',' << s["to_take"].get<int>() << ','
            << FormatNumber(s["position_jump_m"].get<double>()) << ','
            << FormatNumber(s["velocity_jump_m_per_s"].get<double>()) << ','
            << FormatNumber(s["angular_velocity_jump_deg_per_s"].get<double>()) << '\n';
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
}

}  // namespace mmh::pipeline
