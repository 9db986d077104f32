// One tracking run over a frame source, as `mmh track` does it: the proxy tracker and the slider
// reader on every frame, collected into the outputs (trajectory.tum, status.csv, annotation.csv,
// track_summary.json).
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/annotation.h"
#include "core/config.h"
#include "core/trajectory.h"
#include "core/triangle_mesh.h"
#include "track/frame_source.h"
#include "track/freenect_source.h"
#include "track/proxy_tracker.h"
#include "track/setup.h"
#include "track/slider_reader.h"
#include "track/track_section.h"

namespace mmh::track {

// Frame of the written trajectory: camera_T_proxy (the depth camera's frame, as groundtruth.txt
// of a rendered take) or table_T_proxy (the estimated table frame).
enum class OutputFrame { kCamera, kTable };
std::span<const std::pair<OutputFrame, const char*>> EnumNames(OutputFrame);

// Where the track starts: the global detection on the first frame, or the recording's ground
// truth of the first frame (a flag the summary records: accuracy from the tracker's own
// initialisation and from a given one are different claims).
enum class TrackInit { kDetection, kTruth };
std::span<const std::pair<TrackInit, const char*>> EnumNames(TrackInit);

struct TrackOptions {
  OutputFrame output_frame = OutputFrame::kCamera;
  // The model file's unit [m per unit] (0.001 for a model in millimetres).
  double model_scale = 1.0;
  // Read the slider (needs a setup calibration with a Like box).
  bool slider = true;
  // Track the proxy. false: slider-only mode for annotation sessions (the proxy rests outside the
  // play area and the hand moves the slider block): no proxy model is built and no detection runs;
  // the table plane is estimated once (RANSAC on the first frame with a plane, retried every
  // 15 frames until found) and the slider is read on every frame. Every frame's TrackFrameResult
  // is then lost with the reason "proxy not tracked" (frames stays one per frame, for status.csv),
  // the trajectory is empty. Needs slider reading and a setup calibration with a Like box
  // (InputError otherwise).
  bool proxy = true;
  // Intrinsics for a TUM-layout folder without camera.json and without 'freiburg1/2/3' in its
  // name (used only when override_intrinsics is true, then for any folder).
  bool override_intrinsics = false;
  PinholeIntrinsics intrinsics;
  // Stop after this many frames (0: all).
  int max_frames = 0;
  // Real recordings (BOP, YCB-Video: track/recording.h): the first frame's pose from `init`; the
  // object followed (its id in the recording; 0: the only one); frames per second for the
  // timestamps (the formats have none).
  TrackInit init = TrackInit::kDetection;
  int object = 0;
  double frame_rate = 30.0;
  // The play area [m] (0: the setup's): a recording without a taped play area gives a large one
  // (the objects stand anywhere on the table).
  double play_area_width = 0.0;
  double play_area_depth = 0.0;
  // A model larger than this [m, bounding-box diagonal after model_scale] is an input error: a
  // model in millimetres read as metres (1000 times too big) is the usual cause.
  double max_model_size = 3.0;
  // The appearance check's coloured model (tracker.appearance, track/appearance.h): a mesh file
  // (PLY with vertex colours, OBJ with vertex or Kd colours) in --model's frame and unit
  // (model_scale applies), e.g. a textured scan baked to vertex colours beside a plain geometric
  // model. "" (default): --model's own colours, needed only when tracker.appearance.margin > 0.
  std::string appearance_model;

  template <class V>
  void VisitFields(V& v) {
    v("output_frame", output_frame);
    v("model_scale", model_scale);
    v("slider", slider);
    v("proxy", proxy);
    v("override_intrinsics", override_intrinsics);
    v("intrinsics", intrinsics);
    v("max_frames", max_frames);
    v("init", init);
    v("object", object);
    v("frame_rate", frame_rate);
    v("play_area_width", play_area_width);
    v("play_area_depth", play_area_depth);
    v("max_model_size", max_model_size);
    v("appearance_model", appearance_model);
  }
  void Validate(const std::string& prefix) const;
};

// Every section of a track config: "track", "tracker", "slider", "freenect".
struct TrackConfig {
  TrackOptions track;
  ProxyTrackerOptions tracker;
  SliderReaderOptions slider;
  FreenectOptions freenect;

  // InputError for a section "run" (the name of this section before 2026-11) with the hint.
  static TrackConfig FromConfig(const Config& config);
  nlohmann::json ToJson() const;
};

struct TrackSummary {
  int frames = 0;
  int tracked = 0;
  int predicted = 0;
  int lost = 0;
  int detections = 0;  // frames whose pose came from the global detection
  int slider_found = 0;
  double seconds = 0.0;  // tracking and slider reading, reading frames excluded
  // "detection", or "truth" when the first pose came from the ground truth.
  std::string init = "detection";
  // What may make the run miss the object although the input is valid (MinHeightWarning); in
  // track_summary.json as "warnings" when there are any.
  std::vector<std::string> warnings;
  nlohmann::json ToJson() const;
};

struct TrackRun {
  std::vector<TrackFrameResult> frames;
  std::vector<SliderReading> slider;  // empty without slider reading
  // The poses of the frames not lost, in the output frame.
  Trajectory trajectory;
  // One value per frame: the reading, or the last one before it (0 before the first) where the
  // block was not found.
  Annotation annotation;
  std::optional<Rigid3> camera_T_table;
  std::optional<TablePlane> table_plane;
  TrackSummary summary;
};

// Tracks every frame of `source` (progress(done, total or -1) after each). The setup is the
// calibration (track/setup.h); slider reading needs one with a Like box and setup_calibrated
// (without a calibration the table frame is the estimated one, where the Like box is unknown).
// With config.track.proxy false (slider-only mode) `model` is not used (it may be empty), and a
// missing calibration or Like box, or track.slider false, is an InputError before the first frame.
// `initial_camera_T_proxy`: the first frame's pose when config.track.init is truth (required then).
TrackRun RunTracking(FrameSource& source, const TriangleMesh& model, const std::string& model_name,
                     const TrackSetup& setup, bool setup_calibrated, const TrackConfig& config,
                     const std::function<void(int, int)>& progress = {},
                     const std::optional<Rigid3>& initial_camera_T_proxy = std::nullopt);

// The model's smallest width [m]: the least extent of its vertices along any direction (1 000
// directions on a Fibonacci sphere; the smallest of the bounding box's three extents in the
// model's own axes is an upper bound on it). Lying on its flattest side, the object stands this
// high above the table.
double SmallestWidth(const TriangleMesh& model);

// The warning for a segmentation that cuts the object off: the segmentation keeps only points
// more than tracker.segmentation.min_height above the table, so an object whose smallest width is
// less than min_height + kMinVisibleHeight (1 cm: too few points above the cut for the inlier
// share) is hidden or nearly so lying on its flattest side. Empty when the model stands clear.
std::string MinHeightWarning(double smallest_width, double min_height);
inline constexpr double kMinVisibleHeight = 0.01;

// Writes status.csv, annotation.csv (when the slider was read), trajectory.tum (when any frame
// was not lost) and track_summary.json into `out` (created), each atomically. Returns the names
// written.
std::vector<std::string> WriteTrackRun(const std::filesystem::path& out, const TrackRun& run,
                                       const TrackConfig& config);

}  // namespace mmh::track
