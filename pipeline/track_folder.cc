#include "pipeline/track_folder.h"

#include <algorithm>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/mesh_io.h"
#include "core/staged_folder.h"
#include "core/tum_io.h"
#include "metrics/bop_results.h"
#include "track/frame_source.h"
#include "track/freenect_source.h"
#include "track/recording.h"

namespace mmh::pipeline {
namespace {

namespace fs = std::filesystem;

// A model far larger than any tracked object is almost always one in millimetres read as metres.
void CheckModelSize(const TriangleMesh& model, const std::string& name,
                    const track::TrackOptions& options) {
  const Bounds3 bounds = ComputeBounds(model);
  if (bounds.empty()) return;  // LoadMesh has rejected an empty model already
  const double size = (bounds.max - bounds.min).norm();
  if (size > options.max_model_size) {
    throw InputError("--model " + name + ": the model is " + FormatNumber(size) +
                     " m across (bounding-box diagonal, at track.model_scale " +
                     FormatNumber(options.model_scale) +
                     "), expected at most track.max_model_size = " +
                     FormatNumber(options.max_model_size) +
                     " m: a model in millimetres (BOP) needs --set track.model_scale=0.001");
  }
}

// The run's poses (tracked and predicted frames) as BOP results for comparison with published
// methods: the inlier share as the score (0 for a predicted frame), the frame's tracking time.
std::vector<metrics::BopResult> BopResults(const track::TrackRun& run,
                                           const track::RecordingFrameSource& recording,
                                           int object, int scene) {
  std::vector<metrics::BopResult> results;
  for (const track::TrackFrameResult& f : run.frames) {
    if (f.status == track::TrackStatus::kLost) continue;
    metrics::BopResult r;
    r.scene_id = scene;
    r.im_id = recording.frames().at(f.index).image_id;
    r.obj_id = object;
    r.score = f.status == track::TrackStatus::kTracked ? f.inlier_share : 0.0;
    r.camera_T_object = f.camera_T_proxy;
    r.time = f.seconds;
    results.push_back(r);
  }
  return results;
}

// The object a recording's run follows: track.object, or the only one annotated.
int ChooseObject(const track::RecordingFrameSource& recording, int object) {
  const std::vector<int> ids = recording.object_ids();
  std::string list;
  for (int id : ids) list += (list.empty() ? "" : ", ") + std::to_string(id);
  if (object == 0) {
    if (ids.size() == 1) return ids[0];
    ThrowBadValue("track.object", "0 (the only one)",
                  "one of the objects annotated in " + recording.Describe() + ": " + list);
  }
  if (std::find(ids.begin(), ids.end(), object) == ids.end()) {
    ThrowBadValue("track.object", std::to_string(object),
                  "one of the objects annotated in " + recording.Describe() + ": " + list);
  }
  return object;
}

// The first frame's true pose when track.init is truth.
std::optional<Rigid3> FirstTruePose(const std::optional<Trajectory>& truth,
                                    const track::TrackOptions& options) {
  if (options.init != track::TrackInit::kTruth || !truth) return std::nullopt;
  if (truth->empty()) throw InputError("track.init = truth: the object has no ground truth");
  return truth->poses.front();
}

// The setup calibration: --setup, else INPUT/scene.json when present (else none: the table frame
// is the estimated plane's). `file` gets the file used (empty: none).
std::optional<track::TrackSetup> ReadSetup(const TrackInputs& inputs, bool live,
                                           std::string* file) {
  *file = inputs.setup;
  if (file->empty() && !live && fs::exists(fs::path(inputs.input) / "scene.json")) {
    *file = (fs::path(inputs.input) / "scene.json").string();
  }
  if (file->empty()) return std::nullopt;
  return track::ReadSetupJson(*file);
}

// The frame source of --input and, for a real recording, the followed object and its truth.
struct Source {
  std::unique_ptr<track::FrameSource> frames;
  const track::RecordingFrameSource* recording = nullptr;  // a BOP scene or YCB-Video folder
  int object = 0;                                          // the recording's followed object
  std::optional<Trajectory> truth;                         // its ground truth
};

Source OpenSource(const TrackInputs& inputs, const track::TrackConfig& config, bool live) {
  Source source;
  if (live) {
    source.frames = std::make_unique<track::FreenectFrameSource>(config.freenect);
  } else if (track::DetectRecordingLayout(inputs.input)) {
    auto recording =
        std::make_unique<track::RecordingFrameSource>(inputs.input, config.track.frame_rate);
    source.object = ChooseObject(*recording, config.track.object);
    source.truth = recording->Truth(source.object);
    source.recording = recording.get();
    source.frames = std::move(recording);
  } else {
    source.frames = std::make_unique<track::FolderFrameSource>(
        inputs.input, config.track.override_intrinsics
                          ? std::optional<PinholeIntrinsics>(config.track.intrinsics)
                          : std::nullopt);
  }
  return source;
}

}  // namespace

TrackFolderResult TrackToFolder(const TrackInputs& inputs, const track::TrackConfig& config,
                                const fs::path& out, const TrackFolderOptions& options) {
  // Everything is read and checked before the first frame. Slider-only mode (track.proxy false,
  // annotation sessions) needs no model; one given is still read and checked.
  if (inputs.model.empty() && config.track.proxy) {
    throw InputError("--model is required (the proxy's mesh) unless --set track.proxy=false");
  }
  const TriangleMesh model =
      inputs.model.empty() ? TriangleMesh() : LoadMesh(inputs.model, config.track.model_scale);
  const bool live = inputs.input == "freenect";
  if (!live && !fs::is_directory(inputs.input)) {
    ThrowBadValue("--input", "\"" + inputs.input + "\"",
                  "a TUM RGB-D folder or 'freenect' (a Kinect v1 through libfreenect)");
  }
  std::string setup_file;
  const std::optional<track::TrackSetup> setup = ReadSetup(inputs, live, &setup_file);
  if (config.track.proxy) CheckModelSize(model, inputs.model, config.track);
  Source source = OpenSource(inputs, config, live);

  // The outputs are written into a staging folder beside `out` and moved into place whole (a
  // kill or a failure leaves no partial `out`); an `out` that mmh did not write is refused here,
  // before the work.
  StagedFolder staged(out);
  TrackFolderResult result;
  result.calibrated = setup.has_value();
  result.run = track::RunTracking(
      *source.frames, model, inputs.model, setup.value_or(track::TrackSetup()), result.calibrated,
      config, [&](int done, int total) { if (options.progress) options.progress(done, total); },
      FirstTruePose(source.truth, config.track));
  result.source = source.frames->Describe();
  if (result.run.summary.frames == 0) {
    throw InputError("--input " + inputs.input + ": the source delivered no frame");
  }

  const fs::path& stage = staged.staging();
  result.written = track::WriteTrackRun(stage, result.run, config);
  const nlohmann::json resolved = config.ToJson();
  nlohmann::json timings = result.run.summary.ToJson();
  timings["input"] = result.source;
  timings["setup"] = setup_file.empty() ? "none (table frame from the estimated plane)" : setup_file;
  WriteFileAtomically(stage / "config.resolved.json", resolved.dump(2) + "\n");
  const nlohmann::json provenance =
      options.provenance ? options.provenance(resolved, timings)
                         : nlohmann::json{{"writer", "mmh"}, {"seconds", timings}};
  WriteFileAtomically(stage / "run.json", provenance.dump(2) + "\n");
  if (source.truth) {
    WriteTum(stage / "groundtruth.tum", *source.truth,
             "camera_T_object of the followed object, from the recording's ground truth");
    result.written.push_back("groundtruth.tum");
  }
  if (source.recording) {
    const int scene = metrics::SceneIdOfFolder(inputs.input).value_or(0);
    WriteFileAtomically(stage / "results_bop.csv",
                        metrics::FormatBopResults(
                            BopResults(result.run, *source.recording, source.object, scene)));
    result.written.push_back("results_bop.csv");
  }
  result.written.push_back("config.resolved.json");
  result.written.push_back("run.json");
  // Committed even when nothing was tracked: status.csv says why, and is the result.
  staged.Commit();
  return result;
}

}  // namespace mmh::pipeline
