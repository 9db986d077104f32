// `mmh track`: the tracker on a frame source (a TUM RGB-D folder, or a Kinect v1 through
// libfreenect); writes trajectory.tum, status.csv, annotation.csv, track_summary.json,
// config.resolved.json and run.json (docs/tracker.md).

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <algorithm>
#include <memory>
#include <stdexcept>

#include "cli/command_registry.h"
#include "cli/common_flags.h"
#include "cli/provenance.h"
#include "core/atomic_file.h"
#include "core/config.h"
#include "core/error.h"
#include "core/mesh_io.h"
#include "core/staged_folder.h"
#include "core/tum_io.h"
#include "metrics/bop_results.h"
#include "track/frame_source.h"
#include "track/recording.h"
#include "track/freenect_source.h"
#include "track/track_session.h"

namespace mmh::cli {
namespace {

struct TrackArgs {
  CommonFlags common;
  std::string input;
  std::string model;
  std::string setup;
};

// A model far larger than any tracked object is almost always one in millimetres read as metres.
void CheckModelSize(const TriangleMesh& model, const std::string& name,
                    const track::TrackOptions& options) {
  const Bounds3 bounds = ComputeBounds(model);
  if (bounds.empty()) return;  // LoadMesh has rejected an empty model already
  const double size = (bounds.max - bounds.min).norm();
  if (size > options.max_model_size) {
    throw InputError("--model " + name + ": the model is " + FormatNumber(size) +
                     " m across (bounding-box diagonal, at track.model_scale " +
                     FormatNumber(options.model_scale) + "), expected at most track.max_model_size = " +
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

void RunTrack(const TrackArgs& args, const std::vector<std::string>& argv) {
  namespace fs = std::filesystem;
  const Config config = LoadConfig(args.common);
  const track::TrackConfig track_config = track::TrackConfig::FromConfig(config);
  const auto threads = LimitThreads(args.common.threads);

  // Everything is read and checked before the first frame. Slider-only mode (track.proxy false,
  // annotation sessions) needs no model; one given is still read and checked.
  if (args.model.empty() && track_config.track.proxy) {
    throw InputError("--model is required (the proxy's mesh) unless --set track.proxy=false");
  }
  const TriangleMesh model =
      args.model.empty() ? TriangleMesh() : LoadMesh(args.model, track_config.track.model_scale);
  const bool live = args.input == "freenect";
  if (!live && !fs::is_directory(args.input)) {
    ThrowBadValue("--input", "\"" + args.input + "\"",
                  "a TUM RGB-D folder or 'freenect' (a Kinect v1 through libfreenect)");
  }
  track::TrackSetup setup;
  bool calibrated = false;
  std::string setup_file = args.setup;
  if (setup_file.empty() && !live && fs::exists(fs::path(args.input) / "scene.json")) {
    setup_file = (fs::path(args.input) / "scene.json").string();
  }
  if (!setup_file.empty()) {
    setup = track::ReadSetupJson(setup_file);
    calibrated = true;
  }
  if (track_config.track.proxy) CheckModelSize(model, args.model, track_config.track);
  std::unique_ptr<track::FrameSource> source;
  // A real recording with ground truth (BOP scene, YCB-Video folder): the followed object's truth
  // is written beside the trajectory (groundtruth.tum) and may give the first pose.
  std::optional<Trajectory> truth;
  const track::RecordingFrameSource* recording_source = nullptr;
  int object = 0;
  if (live) {
    source = std::make_unique<track::FreenectFrameSource>(track_config.freenect);
  } else if (track::DetectRecordingLayout(args.input)) {
    auto recording =
        std::make_unique<track::RecordingFrameSource>(args.input, track_config.track.frame_rate);
    object = ChooseObject(*recording, track_config.track.object);
    truth = recording->Truth(object);
    recording_source = recording.get();
    source = std::move(recording);
  } else {
    source = std::make_unique<track::FolderFrameSource>(
        args.input, track_config.track.override_intrinsics
                        ? std::optional<PinholeIntrinsics>(track_config.track.intrinsics)
                        : std::nullopt);
  }

  // The outputs are written into a staging folder beside --out and moved into place whole (a
  // kill or a failure leaves no partial --out); an --out that mmh did not write is refused here,
  // before the work.
  const fs::path out = args.common.out_dir;
  StagedFolder staged(out);
  const bool bar = ShowProgress(args.common);
  ProgressBar progress_bar(bar, "track");
  const track::TrackRun run = track::RunTracking(
      *source, model, args.model, setup, calibrated, track_config,
      [&](int done, int total) { progress_bar.Update(done, total); },
      FirstTruePose(truth, track_config.track));
  progress_bar.Finish();
  for (const std::string& warning : run.summary.warnings) std::cerr << "warning: " << warning << "\n";

  if (run.summary.frames == 0) {
    throw InputError("--input " + args.input + ": the source delivered no frame");
  }
  const fs::path& stage = staged.staging();
  std::vector<std::string> written = track::WriteTrackRun(stage, run, track_config);
  const nlohmann::json resolved = track_config.ToJson();
  nlohmann::json timings = run.summary.ToJson();
  timings["input"] = source->Describe();
  timings["setup"] =
      setup_file.empty() ? "none (table frame from the estimated plane)" : setup_file;
  WriteFileAtomically(stage / "config.resolved.json", resolved.dump(2) + "\n");
  WriteFileAtomically(stage / "run.json",
                      Provenance(argv, resolved, args.common.threads, timings).dump(2) + "\n");
  if (truth) {
    WriteTum(stage / "groundtruth.tum", *truth,
             "camera_T_object of the followed object, from the recording's ground truth");
    written.push_back("groundtruth.tum");
  }
  if (recording_source) {
    WriteFileAtomically(stage / "results_bop.csv",
                        metrics::FormatBopResults(BopResults(run, *recording_source, object,
                                                             metrics::SceneIdOfFolder(args.input).value_or(0))));
    written.push_back("results_bop.csv");
  }
  written.push_back("config.resolved.json");
  written.push_back("run.json");
  // Committed even when nothing was tracked below: status.csv says why, and is the result.
  staged.Commit();
  if (!args.common.quiet) {
    const track::TrackSummary& s = run.summary;
    std::cout << "track: " << s.frames << " frames from " << source->Describe() << ": ";
    if (track_config.track.proxy) {
      std::cout << s.tracked << " tracked, " << s.predicted << " predicted, " << s.lost << " lost ("
                << s.detections << " detections)";
    } else {
      std::cout << "proxy not tracked (track.proxy=false)";
    }
    if (!run.slider.empty()) std::cout << "; slider found in " << s.slider_found;
    std::cout << "; " << (s.seconds > 0 ? s.frames / s.seconds : 0.0) << " frames/s\n";
    if (!calibrated) {
      std::cout << "note: no setup calibration (--setup or scene.json): table frame from the "
                   "estimated plane, slider not read\n";
    }
    std::cout << "written: " << out.string() << "/{";
    for (size_t i = 0; i < written.size(); ++i) std::cout << (i ? ", " : "") << written[i];
    std::cout << "}\n";
  }
  if (!track_config.track.proxy) {
    if (run.summary.slider_found == 0) {
      throw std::runtime_error("the slider block was found in no frame; see " +
                               (out / "status.csv").string());
    }
    return;
  }
  if (run.summary.tracked == 0) {
    // A failure of the work, not of the input's form: every frame was lost (status.csv says why).
    throw std::runtime_error("no frame was tracked (a model that does not match the proxy?); see " +
                             (out / "status.csv").string());
  }
}

}  // namespace

void AddTrackCommand(CLI::App& app, const std::vector<std::string>& argv) {
  auto args = std::make_shared<TrackArgs>();
  CLI::App* cmd = app.add_subcommand(
      "track",
      "Tracker on a frame source: proxy trajectory (TUM), per-frame status, slider "
      "annotation (CSV)");
  cmd->add_option("--input", args->input,
                  "A TUM RGB-D folder (ours or a public sequence), a real recording with ground "
                  "truth (BOP scene, YCB-Video folder), or 'freenect' for a Kinect v1")
      ->required();
  cmd->add_option("--model", args->model,
                  "The proxy's mesh (.ply or .obj), e.g. model.ply of a rendered take; "
                  "required unless --set track.proxy=false (slider only)");
  cmd->add_option("--setup", args->setup,
                  "Setup calibration (scene.json keys: camera_T_table, table.play_area_*, "
                  "table.like_box_*); default: INPUT/scene.json when present");
  AddCommonFlags(cmd, &args->common,
                 {.config_help = "JSON config: sections track, tracker, slider, freenect"});
  cmd->callback([args, argv] { RunTrack(*args, argv); });
}

MMH_REGISTER_COMMAND(40, AddTrackCommand);

}  // namespace mmh::cli
