// `mmh run`: one animator end to end (pipeline/animator_run.h), its files (pipeline/run_output.h).
#include "cli/run_command.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli/command_registry.h"
#include "cli/common_flags.h"
#include "cli/provenance.h"
#include "core/atomic_file.h"
#include "core/config.h"
#include "core/error.h"
#include "core/text_parsing.h"
#include "pipeline/animator_run.h"
#include "pipeline/run_metrics.h"
#include "pipeline/run_output.h"
#include "report/run_scene.h"

namespace mmh::cli {
namespace {

struct RunArgs {
  CommonFlags common;
  int animator = -1;
  long long seed = -1;
  bool resume = false;
};

// --resume continues a run whose sessions were made with the same config: only the sections
// that come after the sessions (montage, metrics, run.min_tracked_share) may change.
void CheckResumable(const std::filesystem::path& out, const nlohmann::json& resolved) {
  const std::filesystem::path file = out / "config.resolved.json";
  if (!std::filesystem::exists(file)) {
    ThrowBadValue(file.string(), "missing",
                  "the resolved config of an earlier run in this folder (--resume continues one)");
  }
  nlohmann::json earlier = nlohmann::json::parse(ReadTextFile(file), nullptr, false);
  if (earlier.is_discarded() || !earlier.is_object()) {
    ThrowBadValue(file.string(), "unreadable JSON", "the resolved config mmh run writes");
  }
  nlohmann::json now = resolved;
  for (nlohmann::json* j : {&earlier, &now}) {
    j->erase("montage");
    j->erase("metrics");
    if (j->contains("run")) (*j)["run"].erase("min_tracked_share");
  }
  // The first difference, as a JSON patch from the earlier config to this one.
  const nlohmann::json patch = nlohmann::json::diff(earlier, now);
  if (!patch.empty()) {
    const std::string path = patch[0]["path"].get<std::string>();
    const nlohmann::json::json_pointer pointer(path);
    std::string key = path.empty() ? "" : path.substr(1);
    std::replace(key.begin(), key.end(), '/', '.');
    const std::string value_earlier =
        earlier.contains(pointer) ? earlier[pointer].dump() : "nothing";
    const std::string value_now = now.contains(pointer) ? now[pointer].dump() : "nothing";
    ThrowBadValue(file.string() + ": " + (key.empty() ? "(the whole config)" : key), value_earlier,
                  value_now +
                      " as in this run's config (the sessions would differ; only "
                      "montage, metrics and run.min_tracked_share may change with "
                      "--resume)");
  }
}

}  // namespace

pipeline::AnimatorRun RunScenario(const pipeline::RunConfig& config, int animator,
                                  const std::filesystem::path& out, bool progress_bar,
                                  const std::vector<std::string>& argv, int threads, bool resume) {
  if (!config.run.metrics) {
    ThrowBadValue("run.metrics", "false",
                  "true: mmh run and mmh regress write metrics.json (false is for the replicates "
                  "of mmh study and mmh calibrate)");
  }
  const nlohmann::json resolved = config.ToJson();
  if (resume) CheckResumable(out, resolved);
  EnsureDirectory(out);
  // The resolved config first: whatever fails later, the results beside it say what ran.
  WriteFileAtomically(out / "config.resolved.json", resolved.dump(2) + "\n");
  ProgressBar bar(progress_bar, "run: animator " + std::to_string(animator));
  pipeline::AnimatorRun run;
  try {
    run = pipeline::RunAnimator(
        config, animator, [&](std::int64_t done, std::int64_t total) { bar.Update(done, total); },
        [&](const pipeline::TakeRun& take, bool practice) {
          pipeline::WriteTakeRun(out, take, practice);
        },
        resume ? pipeline::TakeLoader([&](pipeline::TakeRun& take, bool practice) {
          return pipeline::LoadTakeRun(out, take, practice);
        })
               : pipeline::TakeLoader());
  } catch (...) {
    // The takes that finished are on disk; say what ran.
    WriteFileAtomically(out / "run.json",
                        Provenance(argv, resolved, threads, {{"failed", true}}).dump(2) + "\n");
    throw;
  }
  pipeline::WriteAnimatorRun(out, run);
  for (const bool truth : {false, true}) {
    report::WriteGlb(out / (truth ? "montage_truth" : "montage") / "montage.glb",
                     report::RunMontageScene(run, truth, config.montage.reference_take));
  }
  WriteFileAtomically(out / "timings.csv", pipeline::TimingsToCsv(run));
  WriteFileAtomically(
      out / "run.json",
      Provenance(argv, resolved, threads, pipeline::SecondsToJson(run)).dump(2) + "\n");
  return run;
}

namespace {

void RunRun(const RunArgs& args, const std::vector<std::string>& argv) {
  Config config = LoadConfig(args.common);
  if (args.seed >= 0) config.Set("population.seed=" + std::to_string(args.seed));
  if (args.animator >= 0) config.Set("render.animator=" + std::to_string(args.animator));
  const pipeline::RunConfig run_config = pipeline::RunConfig::FromConfig(config);
  const auto threads = LimitThreads(args.common.threads);
  const std::filesystem::path out = args.common.out_dir;
  const bool bar = ShowProgress(args.common);
  const pipeline::AnimatorRun run = RunScenario(run_config, run_config.render.render.animator, out,
                                                bar, argv, args.common.threads, args.resume);
  if (args.common.quiet) return;
  const nlohmann::json& m = run.metrics;
  const nlohmann::json seconds = pipeline::SecondsToJson(run);
  std::printf("run: animator %d, %zu takes of %s (%s fidelity)\n", run.participant.index,
              run.takes.size(), run_config.render.render.story.c_str(),
              EnumName(run_config.run.fidelity));
  for (const nlohmann::json& t : m["takes"]) {
    std::printf(
        "  take %d: %d frames, quality %.3f; tracking %.1f %% within %.0f deg/%.0f mm, median "
        "%.2f deg / %.2f mm, %d lost; slider RMSE %.3f\n",
        t["take"].get<int>(), t["frames"].get<int>(), t["mean_quality"].get<double>(),
        100 * t["tracking"]["success_rate"].get<double>(), run_config.metrics.success_rotation_deg,
        1000 * run_config.metrics.success_translation,
        t["tracking"]["rotation_deg"]["median"].get<double>(),
        1000 * t["tracking"]["translation_m"]["median"].get<double>(),
        t["tracking"]["lost"].get<int>(), t["annotation"]["rmse"].get<double>());
  }
  const nlohmann::json& mt = m["montage"]["tracked"];
  std::printf(
      "  montage: %d frames, %d segments (shortest %d), quality %.3f (best take %+.3f), "
      "constraint +%.2f %%, label agreement with the ground-truth montage %.1f %%\n",
      mt["montage_frames"].get<int>(), mt["segments"].get<int>(),
      mt["shortest_segment_montage_frames"].get<int>(), mt["mean_quality"].get<double>(),
      mt["quality_gain_over_best_take"].get<double>(),
      mt["constraint_increase_percent"].get<double>(),
      100 * m["montage"]["tracked_vs_truth"]["label_agreement"].get<double>());
  std::printf(
      "  time: %.1f s total (record %.1f s, annotate %.1f s, compose %.2f s), %.0f frames/s "
      "through render and track\n",
      seconds["total"].get<double>(), seconds["record"].get<double>(),
      seconds["annotate"].get<double>(), seconds["compose"].get<double>(),
      seconds["render_track_frames_per_second"].get<double>());
  std::printf(
      "written: %s/{metrics.json, metrics.csv, tracking_frames.csv, seams.csv, takes/, "
      "montage/, montage_truth/, timings.csv, config.resolved.json, run.json}\n",
      out.string().c_str());
}

}  // namespace

void AddRunCommand(CLI::App& app, const std::vector<std::string>& argv) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* cmd = app.add_subcommand(
      "run", "One animator end to end: performance -> sensor -> tracker -> montage -> metrics");
  AddCommonFlags(cmd, &args->common,
                 {.config_help = "JSON config (e.g. configs/soldier.json): render sections, "
                                 "tracker, slider, montage, metrics, error_model, run",
                  .config_required = true});
  cmd->add_option("--animator", args->animator, "Participant index (sets render.animator)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--seed", args->seed, "Population seed (sets population.seed)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--resume", args->resume,
                "Reuse the takes an earlier run in --out finished (same config but for montage, "
                "metrics); run the rest");
  cmd->callback([args, argv] { RunRun(*args, argv); });
}

MMH_REGISTER_COMMAND(45, AddRunCommand);

}  // namespace mmh::cli
