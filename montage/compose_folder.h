// `mmh compose`'s output folder: the montage of one object, or of several layered ones, with its
// spatial markers, written whole (core/staged_folder.h). The files are listed in README.md
// ("Composing a montage"): montage.tum, segments.csv, timeline.csv, summary.json, markers.tum,
// config.resolved.json, run.json, and per later object layers/NAME/{montage.tum, segments.csv,
// timeline.csv, summary.json}.
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "core/trajectory.h"
#include "montage/layered.h"

namespace mmh::montage {

// One object of the montage and the files its takes and annotations came from (summary.json's
// take_files and annotation_files).
struct ComposeObjectInput {
  LayeredObject object;
  std::vector<std::string> take_files;
  std::vector<std::string> annotation_files;
};

// The objects as read from their files: TUM takes and annotation CSVs, in order (InputError naming
// the file). `name` becomes the object's folder (layers/NAME) for a later object.
ComposeObjectInput ReadComposeObject(const std::string& name,
                                     const std::vector<std::string>& take_files,
                                     const std::vector<std::string>& annotation_files);

struct ComposeFolderOptions {
  // Spatial markers on the first object's montage timeline: montage frames, at least 60 apart
  // (paper); their poses go to markers.tum.
  std::vector<int> marker_frames;
  // run.json (the caller's provenance) for the resolved config and the timings.
  std::function<nlohmann::json(const nlohmann::json& resolved, const nlohmann::json& timings)>
      provenance;
  // montage.glb's bytes for the composed montages (the CLI's report::EncodeGlb; empty or unset:
  // no montage.glb). Called before anything is written.
  std::function<std::string(const std::vector<Montage>& montages)> glb;
};

struct ComposeFolderResult {
  std::vector<Montage> montages;  // one per object, objects[0] first
  Trajectory marker_poses;        // the first montage's pose at each marker (empty: none)
  std::vector<std::string> written;  // the top-level files (layers/ aside), for messages
};

// Composes the objects (ComposeLayered: the first time-warped as options say, the later ones
// without warping), then writes every file into a staging folder beside `out` and moves it into
// place. Everything is read and computed before the first file is written, so bad input
// (InputError) leaves nothing under `out`. summary.json and every other file but run.json are a
// pure function of the inputs and options (timings go to run.json only, DESIGN.md
// "Determinism").
ComposeFolderResult ComposeToFolder(const std::vector<ComposeObjectInput>& objects,
                                    const ComposeOptions& options,
                                    const std::filesystem::path& out,
                                    const ComposeFolderOptions& folder_options);

}  // namespace mmh::montage
