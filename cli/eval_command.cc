// `mmh eval`: a tracked trajectory (TUM, camera_T_object) against a recording's ground truth with
// the BOP pose errors (ADD, ADD-S, MSSD, MSPD, VSD), BOP's average recall and the 5 deg / 5 cm and
// 2 deg / 2 cm recalls (metrics/pose_evaluation.h); writes eval_frames.csv, eval_objects.csv,
// eval.json, config.resolved.json and run.json.
#include <CLI/CLI.hpp>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli/command_registry.h"
#include "cli/compose_command.h"
#include "cli/provenance.h"
#include "core/atomic_file.h"
#include "core/config.h"
#include "core/error.h"
#include "core/mesh_io.h"
#include "core/rgbd_folder.h"
#include "core/tum_io.h"
#include "metrics/model_symmetries.h"
#include "metrics/pose_evaluation.h"
#include "track/recording.h"
#include "track/track_section.h"

namespace mmh::cli {
namespace {

struct EvalArgs {
  CommonFlags common;
  std::string input;
  std::string estimate;
  std::string truth;
  std::string model;
  std::string models_info;
};

// The object's symmetry transformations from BOP's models_info.json: --models-info, or the
// models_info.json beside the model when there is one (none: the identity only). The file's
// translations are in the model's units (model_scale). Records the file used in *used.
std::vector<Rigid3> ObjectSymmetries(const EvalArgs& args, int object, double model_scale,
                                     double max_step, std::string* used) {
  namespace fs = std::filesystem;
  fs::path path = args.models_info;
  const bool given = !path.empty();
  if (!given) {
    path = fs::path(args.model).parent_path() / "models_info.json";
    if (!fs::exists(path)) return {};
  }
  const auto objects = metrics::ReadModelsInfo(path, model_scale);
  const auto it = objects.find(object);
  if (it == objects.end()) {
    if (given) {
      throw InputError(path.string() + ": no entry for object " + std::to_string(object) +
                       " (track.object)");
    }
    return {};
  }
  *used = path.string();
  std::vector<Rigid3> all = metrics::SymmetryTransformations(it->second, max_step);
  all.erase(all.begin());  // the identity (EvaluateObject implies it)
  return all;
}

// Section "track" (the keys it shares with mmh track's, and the time tolerance).
struct EvalRunOptions {
  // The model file's unit [m per unit] (0.001 for a BOP model in millimetres).
  double model_scale = 1.0;
  // The evaluated object's id in the recording (0: the only one).
  int object = 0;
  // Frames per second of a recording (its timestamps: im_id / frame_rate).
  double frame_rate = 30.0;
  // An estimate belongs to the truth's frame when their timestamps differ by at most this [s].
  double time_tolerance = 1e-3;

  template <class V>
  void VisitFields(V& v) {
    v("model_scale", model_scale);
    v("object", object);
    v("frame_rate", frame_rate);
    v("time_tolerance", time_tolerance);
  }
  void Validate(const std::string& prefix) const {
    RequirePositive(model_scale, prefix + ".model_scale");
    RequirePositive(frame_rate, prefix + ".frame_rate", "Hz");
    RequirePositive(time_tolerance, prefix + ".time_tolerance", "s");
    if (object < 0) ThrowBadValue(prefix + ".object", std::to_string(object), ">= 0");
  }
};

// The estimate whose timestamp is within `tolerance` of t, if any (estimates sorted by time).
std::optional<Rigid3> EstimateAt(const Trajectory& estimates, double t, double tolerance) {
  const auto it = std::lower_bound(estimates.timestamps.begin(), estimates.timestamps.end(),
                                   t - tolerance);
  if (it == estimates.timestamps.end() || *it > t + tolerance) return std::nullopt;
  return estimates.poses[it - estimates.timestamps.begin()];
}

void RunEval(const EvalArgs& args, const std::vector<std::string>& argv) {
  namespace fs = std::filesystem;
  const Config config = LoadConfig(args.common);
  track::RefuseRunSection(config);
  config.RequireOnlySections({"track", "eval"});
  const EvalRunOptions run = config.Get<EvalRunOptions>("track");
  run.Validate("track");
  const metrics::PoseEvaluationOptions options = config.Get<metrics::PoseEvaluationOptions>("eval");
  options.Validate("eval");
  const TriangleMesh model = LoadMesh(args.model, run.model_scale);
  const Trajectory estimates = ReadTum(args.estimate);

  std::vector<metrics::EvaluationFrame> frames;
  int object = run.object;
  std::string description;
  if (!fs::is_directory(args.input)) {
    ThrowBadValue("--input", "\"" + args.input + "\"",
                  "a recording: BOP scene, YCB-Video folder or TUM RGB-D folder with camera.json");
  }
  if (track::DetectRecordingLayout(args.input)) {
    if (!args.truth.empty()) {
      throw InputError("--truth " + args.truth +
                       ": only for TUM folders (a recording's own ground truth is used)");
    }
    track::RecordingFrameSource recording(args.input, run.frame_rate);
    description = recording.Describe();
    const std::vector<int> ids = recording.object_ids();
    if (object == 0) {
      if (ids.size() != 1) {
        ThrowBadValue("track.object", "0 (the only one)",
                      "the id of one of the " + std::to_string(ids.size()) +
                          " objects annotated in " + description);
      }
      object = ids[0];
    }
    const Trajectory truth = recording.Truth(object);
    if (truth.empty()) {
      ThrowBadValue("track.object", std::to_string(object), "an object annotated in " + description);
    }
    RgbdFrame frame;
    for (int k = 0; recording.Next(&frame); ++k) {
      const auto& info = recording.frames()[k];
      for (const auto& t : info.truth) {
        if (t.object_id != object) continue;
        metrics::EvaluationFrame e;
        e.frame = k;
        e.timestamp = frame.timestamp;
        e.camera_T_truth = t.camera_T_object;
        e.camera_T_estimate = EstimateAt(estimates, frame.timestamp, run.time_tolerance);
        e.intrinsics = info.intrinsics;
        e.visible_fraction = t.visible_fraction;
        if (options.vsd && !frame.depth.empty()) {
          e.test_distance = metrics::DepthToDistance(frame.depth, frame.depth_scale, info.intrinsics);
        }
        frames.push_back(std::move(e));
      }
    }
  } else {
    // A TUM folder: the truth from --truth or groundtruth.txt, matched to the depth frames.
    const RgbdFolderReader reader(args.input);
    description = "folder " + args.input;
    const std::optional<Trajectory> truth =
        args.truth.empty() ? reader.ReadGroundtruth() : std::optional<Trajectory>(ReadTum(args.truth));
    if (!truth) {
      throw InputError(args.input + ": no groundtruth.txt (give --truth FILE)");
    }
    for (int k = 0; k < reader.size(); ++k) {
      const double t = reader.depth_timestamp(k);
      const std::optional<Rigid3> true_pose = EstimateAt(*truth, t, run.time_tolerance);
      if (!true_pose) continue;
      metrics::EvaluationFrame e;
      e.frame = k;
      e.timestamp = t;
      e.camera_T_truth = *true_pose;
      e.camera_T_estimate = EstimateAt(estimates, t, run.time_tolerance);
      e.intrinsics = reader.camera().depth_intrinsics;
      if (options.vsd) {
        const RgbdFrame frame = reader.Read(k);
        e.test_distance = metrics::DepthToDistance(frame.depth, frame.depth_scale, e.intrinsics);
      }
      frames.push_back(std::move(e));
    }
  }
  if (frames.empty()) {
    throw InputError(description + ": no frame with ground truth of object " +
                     std::to_string(object));
  }
  std::string models_info;
  const std::vector<Rigid3> symmetries =
      ObjectSymmetries(args, object, run.model_scale, options.max_symmetry_step, &models_info);
  std::vector<metrics::ObjectEvaluation> objects;
  objects.push_back(metrics::EvaluateObject(object, std::move(frames), model, symmetries, options));

  const fs::path out = args.common.out_dir;
  EnsureDirectory(out);
  WriteFileAtomically(out / "eval_frames.csv", metrics::FramesCsv(objects));
  WriteFileAtomically(out / "eval_objects.csv", metrics::ObjectsCsv(objects));
  nlohmann::json result = {{"input", description},
                           {"estimate", args.estimate},
                           {"models_info", models_info.empty() ? nlohmann::json() : nlohmann::json(models_info)},
                           {"objects", {}}};
  for (const auto& o : objects) result["objects"].push_back(metrics::ToJson(o));
  WriteFileAtomically(out / "eval.json", result.dump(2) + "\n");
  const nlohmann::json resolved = {{"track", ToJson(run)}, {"eval", ToJson(options)}};
  WriteFileAtomically(out / "config.resolved.json", resolved.dump(2) + "\n");
  WriteFileAtomically(out / "run.json",
                      Provenance(argv, resolved, args.common.threads, nlohmann::json::object())
                              .dump(2) + "\n");
  if (!args.common.quiet) {
    for (const auto& o : objects) {
      const metrics::BopRecall& r = o.recall;
      std::cout << "eval: object " << o.object << ", " << r.frames << " frames: AR "
                << FormatNumber(std::round(r.ar * 1000) / 1000) << " (VSD "
                << (r.has_vsd ? FormatNumber(std::round(r.ar_vsd * 1000) / 1000) : "-")
                << ", MSSD " << FormatNumber(std::round(r.ar_mssd * 1000) / 1000) << ", MSPD "
                << FormatNumber(std::round(r.ar_mspd * 1000) / 1000) << "), within 5 deg/5 cm "
                << FormatNumber(std::round(r.recall_5deg_5cm * 1000) / 10) << " %, 2 deg/2 cm "
                << FormatNumber(std::round(r.recall_2deg_2cm * 1000) / 10) << " %, median "
                << FormatNumber(std::round(r.median_rotation_deg * 100) / 100) << " deg "
                << FormatNumber(std::round(r.median_translation * 1e5) / 100) << " mm\n";
    }
    std::cout << "written: " << out.string()
              << "/{eval_frames.csv, eval_objects.csv, eval.json, config.resolved.json, run.json}\n";
  }
}

}  // namespace

void AddEvalCommand(CLI::App& app, const std::vector<std::string>& argv) {
  auto args = std::make_shared<EvalArgs>();
  CLI::App* cmd = app.add_subcommand(
      "eval",
      "Pose metrics of a tracked trajectory against a recording's ground truth (BOP: ADD, "
      "ADD-S, MSSD, MSPD, VSD, average recall; 5 deg/5 cm, 2 deg/2 cm)");
  cmd->add_option("--input", args->input,
                  "The recording: BOP scene, YCB-Video folder, or TUM RGB-D folder (camera.json)")
      ->required();
  cmd->add_option("--estimate", args->estimate, "Tracked trajectory (TUM, camera_T_object)")
      ->required();
  cmd->add_option("--model", args->model, "The object's mesh (.ply or .obj)")->required();
  cmd->add_option("--truth", args->truth,
                  "Ground truth (TUM) for a TUM folder; default: its groundtruth.txt");
  cmd->add_option("--models-info", args->models_info,
                  "BOP models_info.json with the object's symmetries (units of the model file); "
                  "default: models_info.json beside --model when there is one");
  cmd->add_option("--config", args->common.config_file, "JSON config: sections track, eval");
  cmd->add_option("--set", args->common.sets, "Override: key.path=value (JSON value), repeatable")
      ->take_all();
  cmd->add_option("--out", args->common.out_dir, "Output folder")->required();
  cmd->add_flag("--quiet", args->common.quiet, "Print nothing on success");
  cmd->callback([args, argv] { RunEval(*args, argv); });
}

MMH_REGISTER_COMMAND(42, AddEvalCommand);

}  // namespace mmh::cli
