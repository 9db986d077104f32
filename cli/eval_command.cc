// `mmh eval`: a tracked trajectory (TUM, camera_T_object) against a recording's ground truth with
// the BOP pose errors (ADD, ADD-S, MSSD, MSPD, VSD), BOP's average recall and the 5 deg / 5 cm and
// 2 deg / 2 cm recalls (metrics/pose_evaluation.h); writes eval_frames.csv, eval_objects.csv,
// eval.json, config.resolved.json and run.json.
#include <CLI/CLI.hpp>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>

#include "cli/command_registry.h"
#include "cli/common_flags.h"
#include "cli/compose_command.h"
#include "cli/provenance.h"
#include "core/atomic_file.h"
#include "core/config.h"
#include "core/error.h"
#include "core/mesh_io.h"
#include "core/rgbd_folder.h"
#include "core/tum_io.h"
#include "metrics/bop_results.h"
#include "metrics/model_symmetries.h"
#include "metrics/pose_evaluation.h"
#include "track/recording.h"
#include "track/track_section.h"

namespace mmh::cli {
namespace {

struct EvalArgs {
  CommonFlags common;
  std::string input;
  std::vector<std::string> estimates;  // [ID=]FILE.tum or a BOP result .csv
  std::string truth;
  std::vector<std::string> models;  // [ID=]MESH
  std::string models_info;
};

// "ID=VALUE" -> (ID, VALUE); "VALUE" -> (nullopt, VALUE).
std::pair<std::optional<int>, std::string> SplitId(const std::string& text) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0 ||
      !std::all_of(text.begin(), text.begin() + eq, [](char c) { return c >= '0' && c <= '9'; })) {
    return {std::nullopt, text};
  }
  return {std::stoi(text.substr(0, eq)), text.substr(eq + 1)};
}

bool IsBopCsv(const std::string& path) {
  return std::filesystem::path(path).extension() == ".csv";
}

// The object's symmetry transformations from BOP's models_info.json: --models-info, or the
// models_info.json beside the model when there is one (none: the identity only). The file's
// translations are in the model's units (model_scale). Records the file used in *used.
std::vector<Rigid3> ObjectSymmetries(const EvalArgs& args, const std::string& model_path,
                                     int object, double model_scale, double max_step,
                                     std::string* used) {
  namespace fs = std::filesystem;
  fs::path path = args.models_info;
  const bool given = !path.empty();
  if (!given) {
    path = fs::path(model_path).parent_path() / "models_info.json";
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

// One evaluated object: its id, mesh, and where its estimates come from.
struct ObjectInput {
  int id = 0;  // 0: the recording's only object
  std::string model_path;
  std::optional<Trajectory> tum;  // else the BOP results
};

// The estimates: TUM files ([ID=]FILE) and BOP result files (.csv, every object's).
struct Estimates {
  std::map<int, Trajectory> tum_by_id;
  std::optional<Trajectory> tum;
  std::vector<metrics::BopResult> bop;
};

Estimates ReadEstimates(const std::vector<std::string>& files) {
  Estimates e;
  for (const std::string& file : files) {
    const auto [id, path] = SplitId(file);
    if (IsBopCsv(path)) {
      if (id) throw InputError("--estimate " + file + ": a BOP result file holds its obj_ids (no ID=)");
      const auto results = metrics::ReadBopResults(path);
      e.bop.insert(e.bop.end(), results.begin(), results.end());
    } else if (id) {
      e.tum_by_id[*id] = ReadTum(path);
    } else {
      if (e.tum) throw InputError("--estimate " + file + ": several TUM estimates need ID=FILE each");
      e.tum = ReadTum(path);
    }
  }
  return e;
}

std::vector<ObjectInput> ObjectInputs(const EvalArgs& args, const EvalRunOptions& run,
                                      const Estimates& estimates) {
  std::vector<ObjectInput> inputs;
  for (const std::string& m : args.models) {
    const auto [id, path] = SplitId(m);
    if (!id && args.models.size() > 1) {
      throw InputError("--model " + m + ": several models need ID=MESH each (the object's id)");
    }
    ObjectInput input;
    input.id = id ? *id : run.object;
    input.model_path = path;
    for (const ObjectInput& other : inputs) {
      if (other.id == input.id) {
        throw InputError("--model " + m + ": object " + std::to_string(input.id) + " given twice");
      }
    }
    if (const auto it = estimates.tum_by_id.find(input.id); it != estimates.tum_by_id.end()) {
      input.tum = it->second;
    } else if (estimates.tum && args.models.size() == 1) {
      input.tum = estimates.tum;
    } else if (estimates.bop.empty()) {
      throw InputError("--model " + m + ": no estimate for object " + std::to_string(input.id) +
                       " (give --estimate " + std::to_string(input.id) +
                       "=FILE.tum or a BOP result .csv)");
    }
    inputs.push_back(std::move(input));
  }
  return inputs;
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
  const Estimates estimates = ReadEstimates(args.estimates);
  std::vector<ObjectInput> inputs = ObjectInputs(args, run, estimates);

  std::vector<std::vector<metrics::EvaluationFrame>> frames(inputs.size());
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
    for (ObjectInput& input : inputs) {
      if (input.id == 0) {
        if (ids.size() != 1) {
          ThrowBadValue("track.object", "0 (the only one)",
                        "the id of one of the " + std::to_string(ids.size()) +
                            " objects annotated in " + description);
        }
        input.id = ids[0];
      }
      if (recording.Truth(input.id).empty()) {
        ThrowBadValue("track.object", std::to_string(input.id),
                      "an object annotated in " + description);
      }
    }
    // The best-scoring BOP result per (image, object) of this scene.
    const std::optional<int> scene = metrics::SceneIdOfFolder(args.input);
    std::map<std::pair<int, int>, metrics::BopResult> bop;
    for (const metrics::BopResult& r : estimates.bop) {
      if (scene && r.scene_id != *scene) continue;
      const auto key = std::make_pair(r.im_id, r.obj_id);
      if (!bop.count(key) || r.score > bop[key].score) bop[key] = r;
    }
    RgbdFrame frame;
    for (int k = 0; recording.Next(&frame); ++k) {
      const auto& info = recording.frames()[k];
      std::vector<float> distance;
      if (options.vsd && !frame.depth.empty()) {
        distance = metrics::DepthToDistance(frame.depth, frame.depth_scale, info.intrinsics);
      }
      for (size_t o = 0; o < inputs.size(); ++o) {
        for (const auto& t : info.truth) {
          if (t.object_id != inputs[o].id) continue;
          metrics::EvaluationFrame e;
          e.frame = k;
          e.timestamp = frame.timestamp;
          e.camera_T_truth = t.camera_T_object;
          if (inputs[o].tum) {
            e.camera_T_estimate = EstimateAt(*inputs[o].tum, frame.timestamp, run.time_tolerance);
          } else if (const auto it = bop.find({info.image_id, inputs[o].id}); it != bop.end()) {
            e.camera_T_estimate = it->second.camera_T_object;
          }
          e.intrinsics = info.intrinsics;
          e.visible_fraction = t.visible_fraction;
          e.test_distance = distance;
          frames[o].push_back(std::move(e));
        }
      }
    }
  } else {
    // A TUM folder: one object, the truth from --truth or groundtruth.txt, matched to the depth
    // frames.
    if (inputs.size() != 1 || !inputs[0].tum) {
      throw InputError("--input " + args.input +
                       ": a TUM folder is evaluated for one object with a TUM estimate");
    }
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
      e.camera_T_estimate = EstimateAt(*inputs[0].tum, t, run.time_tolerance);
      e.intrinsics = reader.camera().depth_intrinsics;
      if (options.vsd) {
        const RgbdFrame frame = reader.Read(k);
        e.test_distance = metrics::DepthToDistance(frame.depth, frame.depth_scale, e.intrinsics);
      }
      frames[0].push_back(std::move(e));
    }
  }
  std::vector<metrics::ObjectEvaluation> objects;
  nlohmann::json models_info = nlohmann::json::object();
  for (size_t o = 0; o < inputs.size(); ++o) {
    if (frames[o].empty()) {
      throw InputError(description + ": no frame with ground truth of object " +
                       std::to_string(inputs[o].id));
    }
    const TriangleMesh model = LoadMesh(inputs[o].model_path, run.model_scale);
    std::string used;
    const std::vector<Rigid3> symmetries =
        ObjectSymmetries(args, inputs[o].model_path, inputs[o].id, run.model_scale,
                         options.max_symmetry_step, &used);
    if (!used.empty()) models_info[std::to_string(inputs[o].id)] = used;
    objects.push_back(
        metrics::EvaluateObject(inputs[o].id, std::move(frames[o]), model, symmetries, options));
  }

  const fs::path out = args.common.out_dir;
  EnsureDirectory(out);
  WriteFileAtomically(out / "eval_frames.csv", metrics::FramesCsv(objects));
  WriteFileAtomically(out / "eval_objects.csv", metrics::ObjectsCsv(objects));
  WriteFileAtomically(out / "eval_overall.csv", metrics::OverallCsv(objects));
  nlohmann::json result = {{"input", description},
                           {"estimates", args.estimates},
                           {"models_info", models_info},
                           {"objects", nlohmann::json::array()},
                           {"overall", ToJson(metrics::PooledRecall(objects))}};
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
              << "/{eval_frames.csv, eval_objects.csv, eval_overall.csv, eval.json, "
                 "config.resolved.json, run.json}\n";
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
  cmd->add_option("--estimate", args->estimates,
                  "Estimates, repeatable: a tracked trajectory (TUM, camera_T_object; ID=FILE "
                  "for one of several objects) or a BOP result file (.csv: scene_id,im_id,obj_id,"
                  "score,R,t,time)")
      ->required();
  cmd->add_option("--model", args->models,
                  "The object's mesh (.ply or .obj), repeatable as ID=MESH to evaluate several "
                  "objects of a recording (the id in the recording)")
      ->required();
  cmd->add_option("--truth", args->truth,
                  "Ground truth (TUM) for a TUM folder; default: its groundtruth.txt");
  cmd->add_option("--models-info", args->models_info,
                  "BOP models_info.json with the object's symmetries (units of the model file); "
                  "default: models_info.json beside --model when there is one");
  AddCommonFlags(cmd, &args->common,
                 {.config_help = "JSON config: sections track, eval", .threads = false});
  cmd->callback([args, argv] { RunEval(*args, argv); });
}

MMH_REGISTER_COMMAND(42, AddEvalCommand);

}  // namespace mmh::cli
