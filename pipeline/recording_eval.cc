#include "pipeline/recording_eval.h"

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/mesh_io.h"
#include "core/options.h"
#include "core/rgbd_folder.h"
#include "core/staged_folder.h"
#include "core/tum_io.h"
#include "metrics/bop_results.h"
#include "metrics/model_symmetries.h"
#include "track/recording.h"

namespace mmh::pipeline {
namespace {

namespace fs = std::filesystem;

// "ID=VALUE" -> (ID, VALUE); "VALUE" -> (nullopt, VALUE).
std::pair<std::optional<int>, std::string> SplitId(const std::string& text) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0 ||
      !std::all_of(text.begin(), text.begin() + eq, [](char c) { return c >= '0' && c <= '9'; })) {
    return {std::nullopt, text};
  }
  return {std::stoi(text.substr(0, eq)), text.substr(eq + 1)};
}

bool IsBopCsv(const std::string& path) { return fs::path(path).extension() == ".csv"; }

// The object's symmetry transformations from BOP's models_info.json: --models-info, or the
// models_info.json beside the model when there is one (none: the identity only). The file's
// translations are in the model's units (model_scale). Records the file used in *used.
std::vector<Rigid3> ObjectSymmetries(const std::string& models_info, const std::string& model_path,
                                     int object, double model_scale, double max_step,
                                     std::string* used) {
  fs::path path = models_info;
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

std::vector<ObjectInput> ObjectInputs(const std::vector<std::string>& models,
                                      const RecordingEvalOptions& options,
                                      const Estimates& estimates) {
  std::vector<ObjectInput> inputs;
  for (const std::string& m : models) {
    const auto [id, path] = SplitId(m);
    if (!id && models.size() > 1) {
      throw InputError("--model " + m + ": several models need ID=MESH each (the object's id)");
    }
    ObjectInput input;
    input.id = id ? *id : options.object;
    input.model_path = path;
    for (const ObjectInput& other : inputs) {
      if (other.id == input.id) {
        throw InputError("--model " + m + ": object " + std::to_string(input.id) + " given twice");
      }
    }
    if (const auto it = estimates.tum_by_id.find(input.id); it != estimates.tum_by_id.end()) {
      input.tum = it->second;
    } else if (estimates.tum && models.size() == 1) {
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

// An object id of 0 (the recording's only object) resolved, and every id checked against the
// recording's annotations.
void ResolveObjectIds(const track::RecordingFrameSource& recording, const std::string& description,
                      std::vector<ObjectInput>* inputs) {
  const std::vector<int> ids = recording.object_ids();
  for (ObjectInput& input : *inputs) {
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
}

// The best-scoring BOP result per (image, object) of the folder's scene.
std::map<std::pair<int, int>, metrics::BopResult> BestBopResults(
    const std::vector<metrics::BopResult>& results, const std::string& folder) {
  const std::optional<int> scene = metrics::SceneIdOfFolder(folder);
  std::map<std::pair<int, int>, metrics::BopResult> best;
  for (const metrics::BopResult& r : results) {
    if (scene && r.scene_id != *scene) continue;
    const auto key = std::make_pair(r.im_id, r.obj_id);
    if (!best.count(key) || r.score > best[key].score) best[key] = r;
  }
  return best;
}

// Per object, the frames of a BOP scene or YCB-Video folder that annotate it, with the estimate
// of that frame (from its TUM trajectory by timestamp, or from the BOP results by image).
std::vector<std::vector<metrics::EvaluationFrame>> RecordingFrames(
    const RecordingEvalInputs& given, const RecordingEvalOptions& options,
    const metrics::PoseEvaluationOptions& evaluation, const Estimates& estimates,
    std::vector<ObjectInput>* inputs, std::string* description) {
  if (!given.truth.empty()) {
    throw InputError("--truth " + given.truth +
                     ": only for TUM folders (a recording's own ground truth is used)");
  }
  track::RecordingFrameSource recording(given.recording, options.frame_rate);
  *description = recording.Describe();
  ResolveObjectIds(recording, *description, inputs);
  const auto bop = BestBopResults(estimates.bop, given.recording);
  std::vector<std::vector<metrics::EvaluationFrame>> frames(inputs->size());
  RgbdFrame frame;
  for (int k = 0; recording.Next(&frame); ++k) {
    const auto& info = recording.frames()[k];
    std::vector<float> distance;
    if (evaluation.vsd && !frame.depth.empty()) {
      distance = metrics::DepthToDistance(frame.depth, frame.depth_scale, info.intrinsics);
    }
    for (size_t o = 0; o < inputs->size(); ++o) {
      const ObjectInput& input = (*inputs)[o];
      for (const auto& t : info.truth) {
        if (t.object_id != input.id) continue;
        metrics::EvaluationFrame e;
        e.frame = k;
        e.timestamp = frame.timestamp;
        e.camera_T_truth = t.camera_T_object;
        if (input.tum) {
          e.camera_T_estimate = EstimateAt(*input.tum, frame.timestamp, options.time_tolerance);
        } else if (const auto it = bop.find({info.image_id, input.id}); it != bop.end()) {
          e.camera_T_estimate = it->second.camera_T_object;
        }
        e.intrinsics = info.intrinsics;
        e.visible_fraction = t.visible_fraction;
        e.test_distance = distance;
        frames[o].push_back(std::move(e));
      }
    }
  }
  return frames;
}

// A TUM folder: one object, the truth from --truth or groundtruth.txt, matched to the depth frames.
std::vector<metrics::EvaluationFrame> TumFolderFrames(
    const RecordingEvalInputs& given, const RecordingEvalOptions& options,
    const metrics::PoseEvaluationOptions& evaluation, const std::vector<ObjectInput>& inputs,
    std::string* description) {
  if (inputs.size() != 1 || !inputs[0].tum) {
    throw InputError("--input " + given.recording +
                     ": a TUM folder is evaluated for one object with a TUM estimate");
  }
  const RgbdFolderReader reader(given.recording);
  *description = "folder " + given.recording;
  const std::optional<Trajectory> truth = given.truth.empty()
                                              ? reader.ReadGroundtruth()
                                              : std::optional<Trajectory>(ReadTum(given.truth));
  if (!truth) throw InputError(given.recording + ": no groundtruth.txt (give --truth FILE)");
  std::vector<metrics::EvaluationFrame> frames;
  for (int k = 0; k < reader.size(); ++k) {
    const double t = reader.depth_timestamp(k);
    const std::optional<Rigid3> true_pose = EstimateAt(*truth, t, options.time_tolerance);
    if (!true_pose) continue;
    metrics::EvaluationFrame e;
    e.frame = k;
    e.timestamp = t;
    e.camera_T_truth = *true_pose;
    e.camera_T_estimate = EstimateAt(*inputs[0].tum, t, options.time_tolerance);
    e.intrinsics = reader.camera().depth_intrinsics;
    if (evaluation.vsd) {
      const RgbdFrame frame = reader.Read(k);
      e.test_distance = metrics::DepthToDistance(frame.depth, frame.depth_scale, e.intrinsics);
    }
    frames.push_back(std::move(e));
  }
  return frames;
}

}  // namespace

void RecordingEvalOptions::Validate(const std::string& prefix) const {
  RequirePositive(model_scale, prefix + ".model_scale");
  RequirePositive(frame_rate, prefix + ".frame_rate", "Hz");
  RequirePositive(time_tolerance, prefix + ".time_tolerance", "s");
  if (object < 0) ThrowBadValue(prefix + ".object", std::to_string(object), ">= 0");
}

RecordingEvaluation EvaluateRecording(const RecordingEvalInputs& given,
                                      const RecordingEvalOptions& options,
                                      const metrics::PoseEvaluationOptions& evaluation) {
  const Estimates estimates = ReadEstimates(given.estimates);
  std::vector<ObjectInput> inputs = ObjectInputs(given.models, options, estimates);
  if (!fs::is_directory(given.recording)) {
    ThrowBadValue("--input", "\"" + given.recording + "\"",
                  "a recording: BOP scene, YCB-Video folder or TUM RGB-D folder with camera.json");
  }
  RecordingEvaluation result;
  std::vector<std::vector<metrics::EvaluationFrame>> frames;
  if (track::DetectRecordingLayout(given.recording)) {
    frames = RecordingFrames(given, options, evaluation, estimates, &inputs, &result.description);
  } else {
    frames = {TumFolderFrames(given, options, evaluation, inputs, &result.description)};
  }
  for (size_t o = 0; o < inputs.size(); ++o) {
    if (frames[o].empty()) {
      throw InputError(result.description + ": no frame with ground truth of object " +
                       std::to_string(inputs[o].id));
    }
    const TriangleMesh model = LoadMesh(inputs[o].model_path, options.model_scale);
    std::string used;
    const std::vector<Rigid3> symmetries =
        ObjectSymmetries(given.models_info, inputs[o].model_path, inputs[o].id,
                         options.model_scale, evaluation.max_symmetry_step, &used);
    if (!used.empty()) result.models_info[inputs[o].id] = used;
    result.objects.push_back(metrics::EvaluateObject(inputs[o].id, std::move(frames[o]), model,
                                                     symmetries, evaluation));
  }
  return result;
}

void WriteRecordingEvaluation(const fs::path& out, const RecordingEvaluation& result,
                              const RecordingEvalInputs& inputs, const nlohmann::json& resolved,
                              const nlohmann::json& provenance) {
  nlohmann::json models_info = nlohmann::json::object();
  for (const auto& [id, file] : result.models_info) models_info[std::to_string(id)] = file;
  nlohmann::json json = {{"input", result.description},
                         {"estimates", inputs.estimates},
                         {"models_info", models_info},
                         {"objects", nlohmann::json::array()},
                         {"overall", ToJson(metrics::PooledRecall(result.objects))}};
  for (const auto& o : result.objects) json["objects"].push_back(metrics::ToJson(o));
  // The folder is complete or absent (a failure or a kill leaves no partial folder).
  StagedFolder staged(out);
  const fs::path& dir = staged.staging();
  WriteFileAtomically(dir / "eval_frames.csv", metrics::FramesCsv(result.objects));
  WriteFileAtomically(dir / "eval_objects.csv", metrics::ObjectsCsv(result.objects));
  WriteFileAtomically(dir / "eval_overall.csv", metrics::OverallCsv(result.objects));
  WriteFileAtomically(dir / "eval.json", json.dump(2) + "\n");
  WriteFileAtomically(dir / "config.resolved.json", resolved.dump(2) + "\n");
  WriteFileAtomically(dir / "run.json", provenance.dump(2) + "\n");
  staged.Commit();
}

}  // namespace mmh::pipeline
