#include "cli/stats_command.h"

#include <CLI/CLI.hpp>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli/command_registry.h"
#include "cli/common_flags.h"
#include "cli/provenance.h"
#include "core/atomic_file.h"
#include "core/config.h"
#include "study/study_analysis.h"
#include "study/study_data.h"

namespace mmh::cli {
namespace {

struct StatsArgs {
  CommonFlags common;
  std::string input;
};

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void RunStats(const StatsArgs& args, const std::vector<std::string>& argv) {
  const auto start = std::chrono::steady_clock::now();
  const Config config = LoadConfig(args.common);
  config.RequireOnlySections({"stats"});
  const auto options = config.Get<study::StudyAnalysisOptions>("stats");
  StartGitCommitLookup();  // for run.json, while the data are read and analysed

  // Everything is read and computed before anything is written: bad input leaves no output.
  const study::StudyData data = study::ReadStudyData(args.input, options.data);
  const double read_seconds = SecondsSince(start);
  const auto analysis_start = std::chrono::steady_clock::now();
  const study::StudyAnalysis analysis = study::AnalyzeStudy(data, options);
  const double analysis_seconds = SecondsSince(analysis_start);

  nlohmann::json resolved;
  resolved["stats"] = ToJson(options);
  nlohmann::json results = analysis.ToJson();
  const std::string report = analysis.Report();

  const std::filesystem::path out = args.common.out_dir;
  EnsureDirectory(out);
  WriteFileAtomically(out / "results.json", results.dump(2) + "\n");
  WriteFileAtomically(out / "tests.csv", analysis.TestsCsv());
  WriteFileAtomically(out / "take_scores.csv", analysis.TakeScoresCsv());
  WriteFileAtomically(out / "animator_scores.csv", analysis.AnimatorScoresCsv());
  WriteFileAtomically(out / "mean_ranks.csv", analysis.MeanRanksCsv());
  WriteFileAtomically(out / "report.txt", report);
  WriteFileAtomically(out / "config.resolved.json", resolved.dump(2) + "\n");
  const nlohmann::json timings = {
      {"read", read_seconds}, {"analysis", analysis_seconds}, {"total", SecondsSince(start)}};
  WriteFileAtomically(out / "run.json",
                      Provenance(argv, resolved, args.common.threads, timings).dump(2) + "\n");
  if (!args.common.quiet) {
    std::cout << report << "written: " << out.string()
              << "/{results.json, tests.csv, take_scores.csv, animator_scores.csv, "
                 "mean_ranks.csv, report.txt, config.resolved.json, run.json}\n";
  }
}

}  // namespace

void AddStatsCommand(CLI::App& app, const std::vector<std::string>& argv) {
  auto args = std::make_shared<StatsArgs>();
  CLI::App* cmd = app.add_subcommand(
      "stats", "The user study's statistics (Friedman, H1-H3, mixed model) on study data (CSV)");
  cmd->add_option("--input", args->input,
                  "Study folder: rankings.csv, comparisons.csv, segment_costs.csv (optional); "
                  "docs/statistics.md")
      ->required();
  AddCommonFlags(cmd, &args->common,
                 {.config_help = "JSON config with a 'stats' section", .threads = false});
  cmd->callback([args, argv] { RunStats(*args, argv); });
}

MMH_REGISTER_COMMAND(60, AddStatsCommand);

}  // namespace mmh::cli
