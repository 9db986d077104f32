#include "track/track_session.h"

#include <chrono>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/tum_io.h"

namespace mmh::track {

std::span<const std::pair<OutputFrame, const char*>> EnumNames(OutputFrame) {
  static constexpr std::pair<OutputFrame, const char*> kNames[] = {{OutputFrame::kCamera, "camera"},
                                                                   {OutputFrame::kTable, "table"}};
  return kNames;
}

void TrackRunOptions::Validate(const std::string& prefix) const {
  RequirePositive(model_scale, prefix + ".model_scale");
  if (override_intrinsics) intrinsics.Validate(prefix + ".intrinsics");
  if (max_frames < 0) {
    ThrowBadValue(prefix + ".max_frames", std::to_string(max_frames), ">= 0 (0: all)");
  }
}

TrackConfig TrackConfig::FromConfig(const Config& config) {
  config.RequireOnlySections({"run", "tracker", "slider", "freenect"});
  TrackConfig c;
  c.run = config.Get<TrackRunOptions>("run");
  c.tracker = config.Get<ProxyTrackerOptions>("tracker");
  c.slider = config.Get<SliderReaderOptions>("slider");
  c.freenect = config.Get<FreenectOptions>("freenect");
  return c;
}

nlohmann::json TrackConfig::ToJson() const {
  return {{"run", mmh::ToJson(run)},
          {"tracker", mmh::ToJson(tracker)},
          {"slider", mmh::ToJson(slider)},
          {"freenect", mmh::ToJson(freenect)}};
}

nlohmann::json TrackSummary::ToJson() const {
  return {{"frames", frames},         {"tracked", tracked},
          {"predicted", predicted},   {"lost", lost},
          {"detections", detections}, {"slider_found", slider_found},
          {"seconds", seconds},       {"frames_per_second", seconds > 0 ? frames / seconds : 0.0}};
}

TrackRun RunTracking(FrameSource& source, const TriangleMesh& model, const std::string& model_name,
                     const TrackSetup& setup, bool setup_calibrated, const TrackConfig& config,
                     const std::function<void(int, int)>& progress) {
  config.run.Validate("run");
  ProxyTracker tracker(model, model_name, setup, config.tracker);
  std::optional<SliderReader> slider;
  if (config.run.slider && setup_calibrated && setup.has_like_box()) {
    slider.emplace(setup, config.slider);
  }
  TrackRun run;
  RgbdFrame frame;
  double last_value = 0.0;
  using Clock = std::chrono::steady_clock;
  while ((config.run.max_frames == 0 || run.summary.frames < config.run.max_frames) &&
         source.Next(&frame)) {
    const auto start = Clock::now();
    const TrackFrameResult result = source.frame_error().empty()
                                        ? tracker.Track(frame)
                                        : tracker.Unreadable(frame, source.frame_error());
    run.frames.push_back(result);
    if (slider) {
      SliderReading reading;
      if (tracker.camera_T_table() && source.frame_error().empty()) {
        reading = slider->Read(frame, *tracker.camera_T_table());
      } else {
        reading.reason = source.frame_error().empty() ? "no table plane yet" : "unreadable frame";
      }
      if (reading.found) last_value = reading.value;
      run.summary.slider_found += reading.found;
      run.slider.push_back(reading);
      run.annotation.timestamps.push_back(frame.timestamp);
      run.annotation.values.push_back(last_value);
    }
    run.summary.seconds += std::chrono::duration<double>(Clock::now() - start).count();
    ++run.summary.frames;
    run.summary.tracked += result.status == TrackStatus::kTracked;
    run.summary.predicted += result.status == TrackStatus::kPredicted;
    run.summary.lost += result.status == TrackStatus::kLost;
    run.summary.detections += result.detected;
    if (result.status != TrackStatus::kLost) {
      Rigid3 pose = result.camera_T_proxy;
      if (config.run.output_frame == OutputFrame::kTable && tracker.camera_T_table()) {
        pose = tracker.camera_T_table()->Inverse() * pose;
      }
      run.trajectory.timestamps.push_back(frame.timestamp);
      run.trajectory.poses.push_back(pose);
    }
    if (progress) progress(run.summary.frames, source.size());
  }
  run.camera_T_table = tracker.camera_T_table();
  run.table_plane = tracker.table_plane();
  return run;
}

namespace {

// A CSV field: quoted when it holds a comma, a quote or a line break (RFC 4180).
std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"') quoted += '"';
    quoted += c == '\n' ? ' ' : c;
  }
  return quoted + "\"";
}

}  // namespace

std::vector<std::string> WriteTrackRun(const std::filesystem::path& out, const TrackRun& run,
                                       const TrackConfig& config) {
  EnsureDirectory(out);
  std::vector<std::string> written;
  std::ostringstream status;
  status << "frame,timestamp,status,detected,points,skin_points,inlier_share,rms_mm,"
            "free_space_violation,slider_found,slider_value,reason\n";
  for (size_t i = 0; i < run.frames.size(); ++i) {
    const TrackFrameResult& r = run.frames[i];
    status << r.index << ',' << FormatNumber(r.timestamp) << ',' << TrackStatusName(r.status) << ','
           << (r.detected ? 1 : 0) << ',' << r.points << ',' << r.skin_points << ','
           << FormatNumber(r.inlier_share) << ',' << FormatNumber(r.rms * 1000) << ','
           << FormatNumber(r.free_space_violation) << ',';
    if (i < run.slider.size()) {
      status << (run.slider[i].found ? 1 : 0) << ','
             << (run.slider[i].found ? FormatNumber(run.slider[i].value) : "");
    } else {
      status << ',';
    }
    status << ',' << CsvField(r.reason) << '\n';
  }
  WriteFileAtomically(out / "status.csv", status.str());
  written.push_back("status.csv");
  if (!run.annotation.values.empty()) {
    WriteAnnotationCsv(out / "annotation.csv", run.annotation);
    written.push_back("annotation.csv");
  }
  if (!run.trajectory.empty()) {
    WriteTum(out / "trajectory.tum", run.trajectory,
             std::string(config.run.output_frame == OutputFrame::kCamera ? "camera_T_proxy"
                                                                         : "table_T_proxy") +
                 " per tracked or predicted frame; lost frames are left out (status.csv)");
    written.push_back("trajectory.tum");
  }
  nlohmann::json summary = run.summary.ToJson();
  if (run.camera_T_table) {
    const Rigid3& c = *run.camera_T_table;
    summary["camera_T_table"] = {
        {"translation", {c.translation.x(), c.translation.y(), c.translation.z()}},
        {"quaternion_xyzw", {c.rotation.x(), c.rotation.y(), c.rotation.z(), c.rotation.w()}}};
  }
  if (run.table_plane) {
    summary["table_plane"] = {
        {"normal",
         {run.table_plane->normal.x(), run.table_plane->normal.y(), run.table_plane->normal.z()}},
        {"camera_height_m", run.table_plane->offset},
        {"inlier_share", run.table_plane->inlier_share},
        {"rms_distance_m", run.table_plane->rms_distance},
        {"planes_found", run.table_plane->candidates}};
  }
  // Timings vary from run to run: they go to run.json, not here (same config, same bytes).
  summary.erase("seconds");
  summary.erase("frames_per_second");
  WriteFileAtomically(out / "track_summary.json", summary.dump(2) + "\n");
  written.push_back("track_summary.json");
  return written;
}

}  // namespace mmh::track
