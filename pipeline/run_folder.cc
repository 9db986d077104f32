#include "pipeline/run_folder.h"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>

#include "core/atomic_file.h"
#include "core/stale_temporaries.h"
#include "core/error.h"
#include "core/json_text.h"
#include "pipeline/run_metrics.h"
#include "pipeline/run_output.h"

namespace mmh::pipeline {

void CheckResumable(const std::filesystem::path& out, const nlohmann::json& resolved) {
  const std::filesystem::path file = out / "config.resolved.json";
  if (!std::filesystem::exists(file)) {
    ThrowBadValue(file.string(), "missing",
                  "the resolved config of an earlier run in this folder (--resume continues one)");
  }
  nlohmann::json earlier = ReadJsonFile(file);
  if (!earlier.is_object()) {
    ThrowBadValue(file.string(), earlier.dump().substr(0, 40), "the resolved config mmh run writes");
  }
  nlohmann::json now = resolved;
  for (nlohmann::json* j : {&earlier, &now}) {
    j->erase("montage");
    j->erase("metrics");
    if (j->contains("run")) (*j)["run"].erase("min_tracked_share");
  }
  // The first difference, as a JSON patch from the earlier config to this one.
  const nlohmann::json patch = nlohmann::json::diff(earlier, now);
  if (patch.empty()) return;
  const std::string path = patch[0]["path"].get<std::string>();
  const nlohmann::json::json_pointer pointer(path);
  std::string key = path.empty() ? "" : path.substr(1);
  std::replace(key.begin(), key.end(), '/', '.');
  const std::string value_earlier = earlier.contains(pointer) ? earlier[pointer].dump() : "nothing";
  const std::string value_now = now.contains(pointer) ? now[pointer].dump() : "nothing";
  ThrowBadValue(file.string() + ": " + (key.empty() ? "(the whole config)" : key), value_earlier,
                value_now +
                    " as in this run's config (the sessions would differ; only montage, metrics "
                    "and run.min_tracked_share may change with --resume)");
}

AnimatorRun RunToFolder(const RunConfig& config, const std::filesystem::path& out,
                        const RunFolderOptions& options) {
  if (!config.run.metrics) {
    ThrowBadValue("run.metrics", "false",
                  "true: mmh run and mmh regress write metrics.json (false is for the replicates "
                  "of mmh study and mmh calibrate)");
  }
  const nlohmann::json resolved = config.ToJson();
  if (options.resume) CheckResumable(out, resolved);
  EnsureDirectory(out);
  // A run killed between a write and its rename left a temporary: this run continues in place.
  RemoveStaleTemporaries(out);
  auto write_provenance = [&](const nlohmann::json& timings) {
    if (options.provenance) {
      WriteFileAtomically(out / "run.json", options.provenance(timings).dump(2) + "\n");
    }
  };
  // The resolved config first: whatever fails later, the results beside it say what ran.
  WriteFileAtomically(out / "config.resolved.json", resolved.dump(2) + "\n");
  AnimatorRun run;
  try {
    run = RunAnimator(
        config, options.progress,
        [&](const TakeRun& take, bool practice) { WriteTakeRun(out, take, practice); },
        options.resume ? TakeLoader([&](TakeRun& take, bool practice) {
          return LoadTakeRun(out, take, practice);
        })
                       : TakeLoader());
  } catch (...) {
    // The takes that finished are on disk; say what ran.
    write_provenance({{"failed", true}});
    throw;
  }
  WriteAnimatorRun(out, run, config.run.fidelity == Fidelity::kFull);
  if (options.write_more) options.write_more(run);
  WriteFileAtomically(out / "timings.csv", TimingsToCsv(run));
  write_provenance(SecondsToJson(run));
  return run;
}

}  // namespace mmh::pipeline
