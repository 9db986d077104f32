#include "track/track_session.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/error_text.h"
#include "core/mesh_io.h"
#include "core/tum_io.h"
#include "track/table_plane.h"

namespace mmh::track {

std::span<const std::pair<OutputFrame, const char*>> EnumNames(OutputFrame) {
  static constexpr std::pair<OutputFrame, const char*> kNames[] = {{OutputFrame::kCamera, "camera"},
                                                                   {OutputFrame::kTable, "table"}};
  return kNames;
}

std::span<const std::pair<TrackInit, const char*>> EnumNames(TrackInit) {
  static constexpr std::pair<TrackInit, const char*> kNames[] = {{TrackInit::kDetection, "detection"},
                                                                 {TrackInit::kTruth, "truth"}};
  return kNames;
}

namespace {

// The appearance check's model (TrackOptions::appearance_model): the file's, else the tracked
// model's own colours when the check is on; nullptr when neither is asked for. A file whose size
// differs from the model's by more than half (another unit, another object) is an InputError.
std::shared_ptr<const AppearanceModel> LoadAppearanceModel(const TriangleMesh& model,
                                                           const std::string& model_name,
                                                           const TrackConfig& config) {
  const std::string& path = config.track.appearance_model;
  if (path.empty()) {
    if (config.tracker.appearance.margin <= 0) return nullptr;
    return std::make_shared<const AppearanceModel>(
        model, "--model " + model_name + " (tracker.appearance.margin > 0 and no "
                   "track.appearance_model: the model's own colours)");
  }
  const std::string where = "track.appearance_model " + path;
  const TriangleMesh coloured = LoadMesh(path, config.track.model_scale);
  auto size = [](const TriangleMesh& mesh) {
    const Bounds3 b = ComputeBounds(mesh);
    return b.empty() ? 0.0 : (b.max - b.min).norm();
  };
  const double model_size = size(model), coloured_size = size(coloured);
  if (!(coloured_size >= model_size / 1.5 && coloured_size <= model_size * 1.5)) {
    throw InputError(where + ": the appearance model is " + FormatNumber(coloured_size) +
                     " m across (bounding-box diagonal, at track.model_scale " +
                     FormatNumber(config.track.model_scale) + "), expected within a factor 1.5 of "
                     "--model's " + FormatNumber(model_size) + " m (the same object, frame and unit)");
  }
  return std::make_shared<const AppearanceModel>(coloured, where);
}

}  // namespace

void TrackOptions::Validate(const std::string& prefix) const {
  RequirePositive(model_scale, prefix + ".model_scale");
  if (object < 0) ThrowBadValue(prefix + ".object", std::to_string(object), ">= 0 (0: the only one)");
  RequirePositive(frame_rate, prefix + ".frame_rate", "Hz");
  RequireNonNegative(play_area_width, prefix + ".play_area_width", "m");
  RequireNonNegative(play_area_depth, prefix + ".play_area_depth", "m");
  RequirePositive(max_model_size, prefix + ".max_model_size", "m");
  if (override_intrinsics) intrinsics.Validate(prefix + ".intrinsics");
  if (max_frames < 0) {
    ThrowBadValue(prefix + ".max_frames", std::to_string(max_frames), ">= 0 (0: all)");
  }
}

TrackConfig TrackConfig::FromConfig(const Config& config) {
  RefuseRunSection(config);
  config.RequireOnlySections({"track", "tracker", "slider", "freenect"});
  TrackConfig c;
  c.track = config.Get<TrackOptions>("track");
  c.tracker = config.Get<ProxyTrackerOptions>("tracker");
  c.slider = config.Get<SliderReaderOptions>("slider");
  c.freenect = config.Get<FreenectOptions>("freenect");
  return c;
}

nlohmann::json TrackConfig::ToJson() const {
  return {{"track", mmh::ToJson(track)},
          {"tracker", mmh::ToJson(tracker)},
          {"slider", mmh::ToJson(slider)},
          {"freenect", mmh::ToJson(freenect)}};
}

nlohmann::json TrackSummary::ToJson() const {
  nlohmann::json json = {{"frames", frames},         {"tracked", tracked},
          {"predicted", predicted},   {"lost", lost},
          {"detections", detections}, {"slider_found", slider_found}, {"init", init},
          {"seconds", seconds},       {"frames_per_second", seconds > 0 ? frames / seconds : 0.0}};
  // Only when there are any: the simulated takes' summaries (and the regression baselines that
  // hold them) stay byte-identical.
  if (!warnings.empty()) json["warnings"] = warnings;
  return json;
}

double SmallestWidth(const TriangleMesh& model) {
  if (model.vertex_count() == 0) return 0.0;
  const auto width = [&](const Eigen::Vector3d& d) {
    const Eigen::VectorXf along = model.vertices * d.normalized().cast<float>();
    return static_cast<double>(along.maxCoeff() - along.minCoeff());
  };
  // Fibonacci sphere, upper half only (the width along d equals the width along -d), then a
  // descent from the best direction in steps that halve down to 0.01 deg: the sphere's 1 000
  // directions lie about 3.6 deg apart, and a box 27 x 87 mm measured 1.8 deg off its thin axis
  // is 2.7 mm thicker.
  constexpr int kDirections = 1000;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  Eigen::Vector3d best = Eigen::Vector3d::UnitZ();
  double smallest = std::numeric_limits<double>::infinity();
  for (int i = 0; i < kDirections; ++i) {
    const double z = 1.0 - (i + 0.5) / kDirections;
    const double r = std::sqrt(1.0 - z * z);
    const Eigen::Vector3d d(r * std::cos(golden * i), r * std::sin(golden * i), z);
    const double w = width(d);
    if (w < smallest) smallest = w, best = d;
  }
  for (double step = 2.0 * std::numbers::pi / 180; step > 1e-4 * std::numbers::pi / 180;) {
    const Eigen::Vector3d u = best.unitOrthogonal(), v = best.cross(u);
    bool moved = false;
    for (const Eigen::Vector3d& t :
         {Eigen::Vector3d(u), Eigen::Vector3d(-u), Eigen::Vector3d(v), Eigen::Vector3d(-v)}) {
      const Eigen::Vector3d d = (best + std::tan(step) * t).normalized();
      const double w = width(d);
      if (w < smallest) smallest = w, best = d, moved = true;
    }
    if (!moved) step /= 2;
  }
  return smallest;
}

std::string MinHeightWarning(double smallest_width, double min_height) {
  if (smallest_width >= min_height + kMinVisibleHeight) return "";
  return "tracker.segmentation.min_height = " + FormatNumber(min_height) +
         " m: the model is " + FormatNumber(std::round(smallest_width * 1e4) / 1e4) +
         " m thick at its thinnest: lying on its flattest side, less than " +
         FormatNumber(kMinVisibleHeight) +
         " m of it would stand above the cut and it would not be found in that pose (lower "
         "min_height; docs/tracker.md, \"Real recordings\")";
}

namespace {

// Slider-only mode (TrackOptions::proxy false): the table frame from one RANSAC plane, found on
// the first frame that has one and retried every kPlaneRetryFrames frames until then (a plane per
// frame would cost more than the slider reading itself).
class SliderOnlyTable {
 public:
  SliderOnlyTable(const TablePlaneOptions& options, const std::optional<Rigid3>& calibration)
      : options_(options), calibration_(calibration) {}

  // The table frame for `frame` (a readable frame), or nullopt with the reason.
  const std::optional<Rigid3>& Update(const RgbdFrame& frame, std::string* why) {
    if (camera_T_table_) return camera_T_table_;
    if (attempted_ && frame.index - last_attempt_ < kPlaneRetryFrames) {
      *why = "no table plane yet (" + last_why_ + ")";
      return camera_T_table_;
    }
    attempted_ = true;
    last_attempt_ = frame.index;
    try {
      frame.depth_intrinsics.Validate("frame intrinsics");
      plane_ = EstimateTablePlane(frame, options_, calibration_, &last_why_);
    } catch (const InputError& e) {
      last_why_ = e.what();
    }
    if (plane_) {
      camera_T_table_ = TableFrameOnPlane(*plane_, calibration_);
      intrinsics_ = frame.depth_intrinsics;
    } else {
      *why = "no table plane yet (" + last_why_ + ")";
    }
    return camera_T_table_;
  }
  // Frames of other intrinsics than the plane's frame are not read (the same check as the
  // tracker's).
  bool SameCamera(const RgbdFrame& frame) const { return frame.depth_intrinsics == intrinsics_; }
  const std::optional<TablePlane>& plane() const { return plane_; }
  const std::optional<Rigid3>& camera_T_table() const { return camera_T_table_; }

 private:
  static constexpr int kPlaneRetryFrames = 15;
  TablePlaneOptions options_;
  std::optional<Rigid3> calibration_;
  std::optional<TablePlane> plane_;
  std::optional<Rigid3> camera_T_table_;
  PinholeIntrinsics intrinsics_;
  bool attempted_ = false;
  int last_attempt_ = 0;
  std::string last_why_;
};

}  // namespace

TrackRun RunTracking(FrameSource& source, const TriangleMesh& model, const std::string& model_name,
                     const TrackSetup& setup, bool setup_calibrated, const TrackConfig& config,
                     const std::function<void(int, int)>& progress,
                     const std::optional<Rigid3>& initial_camera_T_proxy) {
  config.track.Validate("track");
  if (config.track.init == TrackInit::kTruth && !initial_camera_T_proxy && config.track.proxy) {
    throw InputError("track.init = truth needs a recording with ground truth (a BOP scene or a "
                     "YCB-Video folder) for the first frame's pose");
  }
  const bool slider_only = !config.track.proxy;
  if (slider_only) {
    if (!config.track.slider) {
      ThrowBadValue("track.slider", "false", "true when track.proxy is false (nothing would be read)");
    }
    if (!setup_calibrated || !setup.has_like_box()) {
      throw InputError(
          "track.proxy = false (slider-only mode) reads only the slider, which needs a setup "
          "calibration with a Like box (--setup FILE or INPUT/scene.json, table.like_box_length "
          "> 0); " +
          std::string(setup_calibrated ? "the setup's like_box_length is 0"
                                       : "no setup calibration was given"));
    }
    config.tracker.table.Validate("tracker.table");
    setup.Validate("setup");
  }
  // Slider-only mode builds no proxy model (the model may be empty).
  std::optional<ProxyTracker> tracker;
  if (!slider_only) {
    // A recording's play area (TrackOptions::play_area_*) replaces the setup's.
    TrackSetup tracked_setup = setup;
    if (config.track.play_area_width > 0) tracked_setup.play_area_width = config.track.play_area_width;
    if (config.track.play_area_depth > 0) tracked_setup.play_area_depth = config.track.play_area_depth;
    tracker.emplace(model, model_name, tracked_setup, config.tracker);
    if (auto appearance = LoadAppearanceModel(model, model_name, config)) {
      tracker->SetAppearanceModel(std::move(appearance));
    }
    if (config.track.init == TrackInit::kTruth && initial_camera_T_proxy) {
      tracker->Initialize(*initial_camera_T_proxy);
    }
  }
  SliderOnlyTable slider_table(config.tracker.table, setup.camera_T_table);
  std::optional<SliderReader> slider;
  if (config.track.slider && setup_calibrated && setup.has_like_box()) {
    slider.emplace(setup, config.slider);
  }
  TrackRun run;
  run.summary.init = config.track.init == TrackInit::kTruth ? "truth" : "detection";
  if (!slider_only) {
    const std::string warning =
        MinHeightWarning(SmallestWidth(model), config.tracker.segmentation.min_height);
    if (!warning.empty()) run.summary.warnings.push_back(warning);
  }
  RgbdFrame frame;
  double last_value = 0.0;
  int unreadable = 0;
  std::string first_unreadable;
  using Clock = std::chrono::steady_clock;
  while ((config.track.max_frames == 0 || run.summary.frames < config.track.max_frames) &&
         source.Next(&frame)) {
    const auto start = Clock::now();
    const bool readable = source.frame_error().empty();
    if (!readable && first_unreadable.empty()) first_unreadable = source.frame_error();
    unreadable += !readable;
    TrackFrameResult result;
    std::string no_table = "no table plane yet";
    const std::optional<Rigid3>* camera_T_table = nullptr;
    if (tracker) {
      result = readable ? tracker->Track(frame) : tracker->Unreadable(frame, source.frame_error());
      camera_T_table = &tracker->camera_T_table();
    } else {
      result.index = frame.index;
      result.timestamp = frame.timestamp;
      result.reason = readable ? "proxy not tracked" : "unreadable frame: " + source.frame_error();
      if (readable) {
        camera_T_table = &slider_table.Update(frame, &no_table);
        if (*camera_T_table && !slider_table.SameCamera(frame)) {
          camera_T_table = nullptr;
          no_table = "frame size or intrinsics differ from the table plane's frame";
        }
      }
    }
    if (slider) {
      SliderReading reading;
      if (readable && camera_T_table && *camera_T_table) {
        reading = slider->Read(frame, **camera_T_table);
      } else {
        reading.reason = readable ? no_table : "unreadable frame";
      }
      if (reading.found) last_value = reading.value;
      run.summary.slider_found += reading.found;
      run.slider.push_back(reading);
      run.annotation.timestamps.push_back(frame.timestamp);
      run.annotation.values.push_back(last_value);
    }
    result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    run.summary.seconds += result.seconds;
    run.frames.push_back(result);
    ++run.summary.frames;
    run.summary.tracked += result.status == TrackStatus::kTracked;
    run.summary.predicted += result.status == TrackStatus::kPredicted;
    run.summary.lost += result.status == TrackStatus::kLost;
    run.summary.detections += result.detected;
    if (result.status != TrackStatus::kLost) {
      Rigid3 pose = result.camera_T_proxy;
      if (config.track.output_frame == OutputFrame::kTable && tracker->camera_T_table()) {
        pose = tracker->camera_T_table()->Inverse() * pose;
      }
      run.trajectory.timestamps.push_back(frame.timestamp);
      run.trajectory.poses.push_back(pose);
    }
    if (progress) progress(run.summary.frames, source.size());
  }
  // One unreadable frame is lost; a source none of whose frames can be read (8-bit depth PNGs,
  // every image truncated) is bad input, not a failure to track.
  if (run.summary.frames > 0 && unreadable == run.summary.frames) {
    ThrowBadValue(source.Describe(),
                  "no readable frame among " + std::to_string(unreadable) +
                      " (the first: " + EscapeForMessage(first_unreadable, 300) + ")",
                  "frames whose depth and colour images can be read");
  }
  if (tracker) {
    run.camera_T_table = tracker->camera_T_table();
    run.table_plane = tracker->table_plane();
  } else {
    run.camera_T_table = slider_table.camera_T_table();
    run.table_plane = slider_table.plane();
  }
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
             std::string(config.track.output_frame == OutputFrame::kCamera ? "camera_T_proxy"
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
