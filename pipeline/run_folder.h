// `mmh run`'s output folder: one animator's run (RunAnimator) written into a folder as it goes,
// so that a killed or failed run keeps the takes that finished and `--resume` continues it.
// The files are listed in docs/pipeline.md; pipeline/run_output.h writes each of them.
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json_fwd.hpp>

#include "pipeline/animator_run.h"

namespace mmh::pipeline {

struct RunFolderOptions {
  // Reuse the takes an earlier run in the folder finished; the rest is run.
  bool resume = false;
  Progress progress;
  // run.json (the caller's provenance) for the given timings: SecondsToJson of the run, or
  // {"failed": true} when it failed.
  std::function<nlohmann::json(const nlohmann::json& timings)> provenance;
  // Further files made from the finished run (the CLI's montage.glb), written before run.json.
  std::function<void(const AnimatorRun& run)> write_more;
};

// Runs the scenario's participant (RunAnimator) and writes config.resolved.json first, each take
// as soon as its sessions finish (WriteTakeRun), then the montages, metrics and tables
// (WriteAnimatorRun), timings.csv and run.json. The takes that finished stay written when a
// later stage fails (run.json then says "failed"). InputError when config.run.metrics is false
// (the folder holds metrics.json), and with `resume` when the folder's earlier run is not
// resumable (CheckResumable) or its files do not belong to this run.
AnimatorRun RunToFolder(const RunConfig& config, const std::filesystem::path& out,
                        const RunFolderOptions& options);

// --resume continues a run whose sessions were made with the same config: only the sections
// that come after the sessions (montage, metrics, run.min_tracked_share) may differ between the
// folder's config.resolved.json and `resolved`. InputError naming the first differing key with
// both values.
void CheckResumable(const std::filesystem::path& out, const nlohmann::json& resolved);

}  // namespace mmh::pipeline
