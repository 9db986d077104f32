// `mmh track`'s output folder: the tracker (track/track_session.h) on a TUM RGB-D folder, a real
// recording with ground truth (BOP scene, YCB-Video folder: track/recording.h) or a live Kinect v1,
// written whole (core/staged_folder.h): trajectory.tum, status.csv, annotation.csv,
// track_summary.json, config.resolved.json, run.json, and for a recording groundtruth.tum and
// results_bop.csv (BOP's result format, metrics/bop_results.h). It sits in pipeline/ because a
// recording's results join track/ and metrics/.
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "pipeline/animator_run.h"
#include "track/track_session.h"

namespace mmh::pipeline {

// What is tracked, as given on `mmh track`'s command line (messages name the flags).
struct TrackInputs {
  std::string input;  // --input: a folder, or "freenect" (a Kinect v1 through libfreenect)
  std::string model;  // --model: the object's mesh (empty: slider only, track.proxy false)
  std::string setup;  // --setup: the setup calibration (default: INPUT/scene.json when present)
};

struct TrackFolderOptions {
  Progress progress;  // (done, total or -1) after each frame
  // run.json (the caller's provenance) for the resolved config and the timings.
  std::function<nlohmann::json(const nlohmann::json& resolved, const nlohmann::json& timings)>
      provenance;
};

struct TrackFolderResult {
  track::TrackRun run;
  std::string source;  // the frame source, as it describes itself
  bool calibrated = false;  // a setup calibration was given or found (scene.json)
  std::vector<std::string> written;  // the files, for messages
};

// Reads and checks everything before the first frame (InputError naming the flag, file or key:
// a missing --model, an input that is neither a folder nor 'freenect', a model larger than
// track.max_model_size, an object not in the recording), tracks every frame, and moves the folder
// into place whole, also when nothing was tracked (status.csv says why; the caller decides what
// that means). InputError when the source delivered no frame (nothing written).
TrackFolderResult TrackToFolder(const TrackInputs& inputs, const track::TrackConfig& config,
                                const std::filesystem::path& out,
                                const TrackFolderOptions& options);

}  // namespace mmh::pipeline
