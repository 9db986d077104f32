// `mmh study`: the paper's user study on simulated animators and scorers through the real pipeline
// (study/simulated_study.h), its statistics, Figures 8-11, the side-by-side table with the paper,
// and with --replicates the power of each test. docs/study.md describes every output.
#include <CLI/CLI.hpp>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli/command_registry.h"
#include "cli/common_flags.h"
#include "cli/full_executable.h"
#include "cli/provenance.h"
#include "core/config.h"
#include "core/json_text.h"
#include "study/study_folder.h"

namespace mmh::cli {
namespace {

struct StudyArgs {
  CommonFlags common;
  int replicates = 0;  // 0: study.replicates of the config
  std::string paper_reported =
      (std::filesystem::path(MMH_SOURCE_DIR) / "configs" / "paper_reported.json").string();
};

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void RunStudy(const StudyArgs& args, const std::vector<std::string>& argv) {
  const auto start = std::chrono::steady_clock::now();
  Config config = LoadConfig(args.common);
  if (args.replicates > 0) config.Set("study.replicates=" + std::to_string(args.replicates));
  const study::StudyConfig study_config = study::StudyConfig::FromConfig(config);
  study_config.study.Validate("study");
  RequireFidelityHere(study_config.run.run.fidelity == pipeline::Fidelity::kFull, argv);
  const nlohmann::json paper = ReadJsonFile(args.paper_reported);
  const auto threads = LimitThreads(args.common.threads);

  // Everything is computed before anything is written: bad input or a failed run leaves no output.
  const int replicates = study_config.study.replicates;
  const bool bar = ShowProgress(args.common);
  // One bar over every animator of every replicate.
  ProgressBar progress_bar(bar, "study", "animators");
  const study::StudyResults results = study::RunStudyReplicates(
      study_config, paper, [&](int replicate, int done, int total) {
        progress_bar.Update(std::int64_t{replicate} * total + done,
                            std::int64_t{replicates} * total);
      });
  progress_bar.Finish();

  const nlohmann::json resolved = study_config.ToJson();
  study::WriteStudyFolder(
      args.common.out_dir, study_config, results,
      {.config_file = args.common.config_file,
       .git_commit = GitCommit(),
       .provenance = [&](nlohmann::json timings) {
         timings["total"] = SecondsSince(start);
         return Provenance(argv, resolved, args.common.threads, timings);
       }});
  if (!args.common.quiet) {
    std::cout << results.report << "\nstudy: " << replicates << " replicate(s) of "
              << study_config.study.animators << " animators in " << SecondsSince(start)
              << " s\nwritten: " << args.common.out_dir
              << "/{rankings.csv, comparisons.csv, segment_costs.csv, results.json, tests.csv, "
                 "take_scores.csv, animator_scores.csv, mean_ranks.csv, animators.csv, "
                 "figure8..11 .svg/.csv, paper_comparison.md/.csv, "
              << (replicates > 1 ? "replicates.csv, power.csv, " : "")
              << "report.txt, config.resolved.json, run.json}\n";
  }
}

}  // namespace

void AddStudyCommand(CLI::App& app, const std::vector<std::string>& argv) {
  auto args = std::make_shared<StudyArgs>();
  CLI::App* cmd = app.add_subcommand(
      "study", "The paper's user study on simulated animators and scorers through the pipeline");
  AddCommonFlags(cmd, &args->common,
                 {.config_help = "JSON config (configs/study_soldier.json): the run sections and "
                                 "study, scorers, viewer, self_appraisal"});
  cmd->add_option("--replicates", args->replicates,
                  "Independent studies (power of each test); overrides study.replicates")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--paper-reported", args->paper_reported,
                  "The paper's reported numbers (default: configs/paper_reported.json)");
  cmd->callback([args, argv] { RunStudy(*args, argv); });
}

MMH_REGISTER_COMMAND(55, AddStudyCommand);

}  // namespace mmh::cli
