// `mmh eval`'s work: estimates of one or more objects (tracked TUM trajectories or BOP result
// files) matched to a recording's frames and ground truth, then scored per object with the BOP
// pose errors and recalls (metrics/pose_evaluation.h). The recording is a BOP scene, a YCB-Video
// folder (track/recording.h) or a TUM RGB-D folder with its groundtruth.txt. It sits in pipeline/
// because it joins track/'s recording readers and metrics/; it calls no heavy library (the light
// `mmh` runs it, docs/architecture.md "Start-up").
#pragma once

#include <filesystem>
#include <map>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "metrics/pose_evaluation.h"

namespace mmh::pipeline {

// Section "track" of `mmh eval` (the keys it shares with mmh track's, and the time tolerance).
struct RecordingEvalOptions {
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
  void Validate(const std::string& prefix) const;
};

// What is evaluated, as given on `mmh eval`'s command line (messages name the flags).
struct RecordingEvalInputs {
  std::string recording;                // --input: the recording's folder
  std::vector<std::string> estimates;   // --estimate: [ID=]FILE.tum, or a BOP result .csv
  std::vector<std::string> models;      // --model: [ID=]MESH (.ply, .obj)
  std::string truth;                    // --truth: TUM ground truth of a TUM folder (optional)
  std::string models_info;              // --models-info: BOP models_info.json (optional)
};

struct RecordingEvaluation {
  std::string description;  // the recording, as its reader describes it
  std::vector<metrics::ObjectEvaluation> objects;  // one per --model, in order
  std::map<int, std::string> models_info;  // object id -> the models_info.json its symmetries came from
};

// Reads the estimates, the recording's frames and truth, and the models, and evaluates every
// object. InputError (naming the flag, file or key and the value) for a missing or ambiguous
// estimate, an object not annotated in the recording, a TUM folder without ground truth, or an
// object without any frame of ground truth.
RecordingEvaluation EvaluateRecording(const RecordingEvalInputs& inputs,
                                      const RecordingEvalOptions& options,
                                      const metrics::PoseEvaluationOptions& evaluation);

// eval_frames.csv, eval_objects.csv, eval_overall.csv, eval.json, config.resolved.json
// (`resolved`) and run.json (`provenance`), written whole into `out` (core/staged_folder.h).
void WriteRecordingEvaluation(const std::filesystem::path& out, const RecordingEvaluation& result,
                              const RecordingEvalInputs& inputs, const nlohmann::json& resolved,
                              const nlohmann::json& provenance);

}  // namespace mmh::pipeline
