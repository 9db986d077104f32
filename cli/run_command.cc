// `mmh run`: one animator end to end (pipeline/animator_run.h), its files (pipeline/run_output.h).
#include "cli/run_command.h"

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli/command_registry.h"
#include "cli/common_flags.h"
#include "cli/full_executable.h"
#include "cli/provenance.h"
#include "core/config.h"
#include "core/error.h"
#include "pipeline/animator_run.h"
#include "pipeline/run_metrics.h"
#include "pipeline/run_folder.h"
#include "report/run_scene.h"

namespace mmh::cli {
namespace {

struct RunArgs {
  CommonFlags common;
  int animator = -1;
  long long seed = -1;
  bool resume = false;
};

}  // namespace

pipeline::AnimatorRun RunScenario(const pipeline::RunConfig& config,
                                  const std::filesystem::path& out, bool progress_bar,
                                  const std::vector<std::string>& argv, int threads, bool resume) {
  ProgressBar bar(progress_bar,
                  "run: animator " + std::to_string(config.people.scenario.animator));
  const nlohmann::json resolved = config.ToJson();
  pipeline::RunFolderOptions options;
  options.resume = resume;
  options.progress = [&](std::int64_t done, std::int64_t total) { bar.Update(done, total); };
  options.provenance = [&](const nlohmann::json& timings) {
    return Provenance(argv, resolved, threads, timings);
  };
  options.write_more = [&](const pipeline::AnimatorRun& run) {
    for (const bool truth : {false, true}) {
      report::WriteGlb(out / (truth ? "montage_truth" : "montage") / "montage.glb",
                       report::RunMontageScene(run, truth, config.montage.reference_take));
    }
  };
  return pipeline::RunToFolder(config, out, options);
}

namespace {

void RunRun(const RunArgs& args, const std::vector<std::string>& argv) {
  Config config = LoadConfig(args.common);
  if (args.seed >= 0) config.Set("population.seed=" + std::to_string(args.seed));
  if (args.animator >= 0) config.Set("scenario.animator=" + std::to_string(args.animator));
  const pipeline::RunConfig run_config = pipeline::RunConfig::FromConfig(config);
  RequireFidelityHere(run_config.run.fidelity == pipeline::Fidelity::kFull, argv);
  const auto threads = LimitThreads(args.common.threads);
  const std::filesystem::path out = args.common.out_dir;
  const bool bar = ShowProgress(args.common);
  const pipeline::AnimatorRun run =
      RunScenario(run_config, out, bar, argv, args.common.threads, args.resume);
  if (args.common.quiet) return;
  const pipeline::RunMetrics& m = *run.metrics;
  std::printf("run: animator %d, %zu takes of %s (%s fidelity)\n", run.participant.index,
              run.takes.size(), run_config.people.scenario.story.c_str(),
              EnumName(run_config.run.fidelity));
  for (const pipeline::TakeMetrics& t : m.takes) {
    std::printf(
        "  take %d: %d frames, quality %.3f; tracking %.1f %% within %.0f deg/%.0f mm, median "
        "%.2f deg / %.2f mm, %d lost; slider RMSE %.3f\n",
        t.take, t.frames, t.mean_quality, 100 * t.tracking.summary.success_rate,
        run_config.metrics.success_rotation_deg, 1000 * run_config.metrics.success_translation,
        t.tracking.rotation_deg.median, 1000 * t.tracking.translation_m.median, t.tracking.lost,
        t.annotation.errors.rmse);
  }
  const pipeline::MontageMetrics& mt = m.tracked;
  std::printf(
      "  montage: %d frames, %d segments (shortest %d), quality %.3f (best take %+.3f), "
      "constraint +%.2f %%, label agreement with the ground-truth montage %.1f %%\n",
      mt.compose.montage_frames, mt.segments, mt.compose.shortest_segment_montage,
      mt.mean_quality, mt.quality_gain_over_best_take, mt.compose.constraint_increase_percent,
      100 * m.tracked_vs_truth.label_agreement);
  const pipeline::StageSeconds& seconds = run.seconds;
  std::printf(
      "  time: %.1f s total (record %.1f s, annotate %.1f s, compose %.2f s), %.0f frames/s "
      "through render and track\n",
      seconds.total, seconds.record, seconds.annotate, seconds.compose,
      pipeline::RenderTrackFramesPerSecond(run));
  std::printf(
      "written: %s/{metrics.json, metrics.csv, tracking_frames.csv, %sseams.csv, takes/, "
      "montage/, montage_truth/, timings.csv, config.resolved.json, run.json}\n",
      out.string().c_str(), run_config.run.fidelity == pipeline::Fidelity::kFull ? "tracking_errors.csv, " : "");
}

}  // namespace

void AddRunCommand(CLI::App& app, const std::vector<std::string>& argv) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* cmd = app.add_subcommand(
      "run", "One animator end to end: performance -> sensor -> tracker -> montage -> metrics");
  AddCommonFlags(cmd, &args->common,
                 {.config_help = "JSON config (e.g. configs/soldier.json): scenario, people, "
                                 "render sections, tracker, slider, montage, metrics, "
                                 "error_model, run",
                  .config_required = true});
  cmd->add_option("--animator", args->animator, "Participant index (sets scenario.animator)")
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
