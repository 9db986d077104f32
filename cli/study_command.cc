// `mmh study`: the paper's user study on simulated animators and scorers through the real pipeline
// (study/simulated_study.h), its statistics, Figures 8-11, the side-by-side table with the paper,
// and with --replicates the power of each test. docs/study.md describes every output.
#include <tbb/global_control.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include "cli/command_registry.h"
#include "cli/common_flags.h"
#include "cli/provenance.h"
#include "pipeline/run_metrics.h"
#include "core/atomic_file.h"
#include "core/config.h"
#include "core/error.h"
#include "core/rgbd_folder.h"
#include "study/figures.h"
#include "study/paper_comparison.h"
#include "study/simulated_study.h"

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

nlohmann::json LoadJson(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot be read (expected the paper's reported numbers)");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(path + ": not valid JSON: " + e.what());
  }
}

nlohmann::json DesignJson(const study::ScoringDesign& design, const study::StudyData& data) {
  return {{"animators", design.animators},
          {"takes", design.takes},
          {"scorers", design.scorers},
          {"animator_scorers", design.animators},
          {"comparisons", design.comparisons.size()},
          {"rankings", data.rankings.size()}};
}

nlohmann::json AnimatorJson(const study::AnimatorOutcome& a) {
  nlohmann::json takes = nlohmann::json::array();
  for (std::size_t k = 0; k < a.take_appeal.size(); ++k) {
    takes.push_back({{"skill", a.take_skill[k]},
                     {"mean_quality", a.take_quality[k]},
                     {"appeal", a.take_appeal[k].appeal},
                     {"artefacts_per_minute", a.take_appeal[k].artefacts_per_minute}});
  }
  return {{"id", a.id},
          {"skill", a.skill},
          {"takes", takes},
          {"montage",
           {{"mean_quality", a.montage_appeal.mean_quality},
            {"appeal", a.montage_appeal.appeal},
            {"artefacts_per_minute", a.montage_appeal.artefacts_per_minute},
            {"segment_takes", a.montage_takes},
            {"total_cost", a.montage_summary.total_cost},
            {"unconstrained_cost", a.montage_summary.unconstrained_cost},
            {"constraint_increase_percent", a.montage_summary.constraint_increase_percent},
            {"unconstrained_short_segments", a.montage_summary.unconstrained_short_segments}}},
          {"truth_montage_appeal", a.truth_montage_appeal
                                       ? nlohmann::json(a.truth_montage_appeal->appeal)
                                       : nlohmann::json(nullptr)},
          {"rendered_frames", a.rendered_frames},
          {"metrics", a.metrics ? pipeline::ToJson(*a.metrics) : nlohmann::json(nullptr)}};
}

void RunStudy(const StudyArgs& args, const std::vector<std::string>& argv) {
  const auto start = std::chrono::steady_clock::now();
  Config config;
  if (!args.common.config_file.empty()) config = Config::Load(args.common.config_file);
  for (const auto& set : args.common.sets) config.Set(set);
  if (args.replicates > 0) config.Set("study.replicates=" + std::to_string(args.replicates));
  const study::StudyConfig study_config = study::StudyConfig::FromConfig(config);
  study_config.study.Validate("study");
  const nlohmann::json paper = LoadJson(args.paper_reported);
  std::unique_ptr<tbb::global_control> threads;
  if (args.common.threads > 0) {
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    args.common.threads);
  }

  // Everything is computed before anything is written: bad input or a failed run leaves no output.
  const int replicates = study_config.study.replicates;
  const bool bar = ShowProgress(args.common);
  std::optional<study::SimulatedStudy> first;
  std::vector<study::StudyAnalysis> analyses;
  std::string replicates_csv = study::ReplicatesCsvHeader();
  double animator_seconds = 0, scoring_seconds = 0;
  for (int r = 0; r < replicates; ++r) {
    study::SimulatedStudy s =
        study::RunSimulatedStudy(study_config.ForReplicate(r), r, [&](int done, int total) {
          if (bar) {
            std::cerr << "\rstudy: replicate " << r + 1 << " / " << replicates << ", animator "
                      << done << " / " << total << std::flush;
          }
        });
    animator_seconds += s.animator_seconds;
    scoring_seconds += s.scoring_seconds;
    replicates_csv += study::ReplicateCsvRow(r, s.analysis);
    analyses.push_back(s.analysis);
    if (r == 0) {
      first = std::move(s);
    } else {
      s.animators.clear();
    }
  }
  if (bar) std::cerr << '\n';
  const study::SimulatedStudy& s = *first;
  const auto figures = study::StudyFigures(s.data, s.analysis);
  const auto comparison =
      study::CompareWithPaper(s.analysis, paper, study_config.study.alpha, s.design.scorers);
  std::vector<study::PowerEstimate> power;
  if (replicates > 1) {
    power = study::EstimatePower(analyses, study_config.study.alpha,
                                 study_config.study.analysis.conf_level);
  }

  nlohmann::json results;
  results["replicate"] = 0;
  results["replicates"] = replicates;
  results["design"] = DesignJson(s.design, s.data);
  results["analysis"] = s.analysis.ToJson();
  nlohmann::json animators = nlohmann::json::array();
  for (const auto& a : s.animators) animators.push_back(AnimatorJson(a));
  results["animators"] = animators;
  results["rendered_frames"] = s.rendered_frames;
  if (s.measured_error_model) results["measured_error_model"] = s.measured_error_model->ToJson();
  nlohmann::json paper_json = nlohmann::json::array();
  for (const auto& l : comparison) {
    paper_json.push_back({{"quantity", l.quantity},
                          {"paper", l.paper},
                          {"simulated", l.ours},
                          {"same_conclusion", l.same_conclusion}});
  }
  results["paper_comparison"] = paper_json;
  std::string power_csv =
      "id,description,replicates,significant,rate,conf_low,conf_high,"
      "paper_significant\n";
  if (!power.empty()) {
    nlohmann::json p = nlohmann::json::array();
    for (const auto& e : power) {
      p.push_back(study::ToJson(e));
      power_csv += e.id + ",\"" + e.description + "\"," + std::to_string(e.replicates) + "," +
                   std::to_string(e.significant) + "," + FormatNumber(e.power) + "," +
                   FormatNumber(e.conf_low) + "," + FormatNumber(e.conf_high) + "," +
                   (e.paper_significant ? "1" : "0") + "\n";
    }
    results["power"] = p;
  }
  const nlohmann::json resolved = study_config.ToJson();
  std::string report = s.analysis.Report();
  report += "\nSimulated study beside the paper (replicate 0):\n\n" +
            study::ComparisonMarkdown(comparison);
  if (!power.empty()) {
    report += "\nOver " + std::to_string(replicates) + " replicates, share with p < " +
              FormatNumber(study_config.study.alpha) + ":\n";
    for (const auto& e : power) {
      report += "  " + e.id + ": " + std::to_string(e.significant) + " / " +
                std::to_string(e.replicates) + " = " + FormatNumber(e.power) + " [" +
                FormatNumber(e.conf_low) + ", " + FormatNumber(e.conf_high) + "]\n";
    }
  }

  // Complete or absent: every file goes into a staging folder renamed into place at the end (a
  // kill while writing leaves no partial --out; the next run removes the staging folder).
  StagedFolder staged(args.common.out_dir);
  const std::filesystem::path& out = staged.staging();
  study::WriteStudyData(out, s.data);
  WriteFileAtomically(out / "results.json", results.dump(2) + "\n");
  WriteFileAtomically(out / "tests.csv", s.analysis.TestsCsv());
  WriteFileAtomically(out / "take_scores.csv", s.analysis.TakeScoresCsv());
  WriteFileAtomically(out / "animator_scores.csv", s.analysis.AnimatorScoresCsv());
  WriteFileAtomically(out / "mean_ranks.csv", s.analysis.MeanRanksCsv());
  WriteFileAtomically(out / "animators.csv", study::AnimatorsCsv(s.animators));
  for (const auto& f : figures) {
    WriteFileAtomically(out / (f.name + ".svg"), f.svg);
    WriteFileAtomically(out / (f.name + ".csv"), f.csv);
  }
  WriteFileAtomically(out / "paper_comparison.md", study::ComparisonMarkdown(comparison));
  WriteFileAtomically(out / "paper_comparison.csv", study::ComparisonCsv(comparison));
  if (replicates > 1) {
    WriteFileAtomically(out / "replicates.csv", replicates_csv);
    WriteFileAtomically(out / "power.csv", power_csv);
  }
  if (s.measured_error_model) {
    // The fit as pipeline/error_model.inc: copying it there makes it the fast mode's defaults.
    const std::string origin =
        "the full-fidelity study of " +
        (args.common.config_file.empty() ? std::string("the defaults") : args.common.config_file) +
        " (" + std::to_string(s.animators.size()) + " animators, population seed " +
        std::to_string(study_config.run.render.population.seed) + ") at commit " + GitCommit() +
        ".";
    WriteFileAtomically(out / "error_model.inc", s.measured_error_model->DefaultsSource(origin));
  }
  WriteFileAtomically(out / "report.txt", report);
  WriteFileAtomically(out / "config.resolved.json", resolved.dump(2) + "\n");
  // CPU-side stage times summed over replicate 0's animators (they overlap in wall time).
  pipeline::StageSeconds stages;
  for (const auto& a : s.animators) {
    stages.perform += a.seconds.perform;
    stages.record += a.seconds.record;
    stages.annotate += a.seconds.annotate;
    stages.compose += a.seconds.compose;
    stages.metrics += a.seconds.metrics;
    stages.total += a.seconds.total;
  }
  const nlohmann::json timings = {{"animators", animator_seconds},
                                  {"animator_stages_replicate0",
                                   {{"perform", stages.perform},
                                    {"record", stages.record},
                                    {"annotate", stages.annotate},
                                    {"compose", stages.compose},
                                    {"metrics", stages.metrics},
                                    {"total", stages.total}}},
                                  {"scoring_and_analysis", scoring_seconds},
                                  {"rendered_frames", s.rendered_frames},
                                  {"total", SecondsSince(start)}};
  WriteFileAtomically(out / "run.json",
                      Provenance(argv, resolved, args.common.threads, timings).dump(2) + "\n");
  staged.Commit();
  if (!args.common.quiet) {
    std::cout << report << "\nstudy: " << replicates << " replicate(s) of "
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
