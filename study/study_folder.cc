#include "study/study_folder.h"

#include <nlohmann/json.hpp>
#include <utility>

#include "core/atomic_file.h"
#include "core/staged_folder.h"
#include "core/text_parsing.h"
#include "pipeline/run_metrics.h"
#include "pipeline/tracking_frames.h"

namespace mmh::study {
namespace {

nlohmann::json DesignJson(const ScoringDesign& design, const StudyData& data) {
  return {{"animators", design.animators},
          {"takes", design.takes},
          {"scorers", design.scorers},
          {"animator_scorers", design.animators},
          {"comparisons", design.comparisons.size()},
          {"rankings", data.rankings.size()}};
}

nlohmann::json AnimatorJson(const AnimatorOutcome& a) {
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

// results.json: replicate 0's design, analysis, animators and comparison with the paper, and
// the power of each test.
nlohmann::json ResultsJson(const StudyResults& r, int replicates) {
  const SimulatedStudy& s = r.first;
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
  for (const auto& l : r.comparison) {
    paper_json.push_back({{"quantity", l.quantity},
                          {"paper", l.paper},
                          {"simulated", l.ours},
                          {"same_conclusion", l.same_conclusion}});
  }
  results["paper_comparison"] = paper_json;
  if (!r.power.empty()) {
    nlohmann::json p = nlohmann::json::array();
    for (const auto& e : r.power) p.push_back(ToJson(e));
    results["power"] = p;
  }
  return results;
}

std::string PowerCsv(const std::vector<PowerEstimate>& power) {
  std::string csv =
      "id,description,replicates,significant,rate,conf_low,conf_high,paper_significant\n";
  for (const auto& e : power) {
    csv += e.id + ",\"" + e.description + "\"," + std::to_string(e.replicates) + "," +
           std::to_string(e.significant) + "," + FormatNumber(e.power) + "," +
           FormatNumber(e.conf_low) + "," + FormatNumber(e.conf_high) + "," +
           (e.paper_significant ? "1" : "0") + "\n";
  }
  return csv;
}

std::string ReportText(const StudyResults& r, const StudyConfig& config) {
  std::string report = r.first.analysis.Report();
  report += "\nSimulated study beside the paper (replicate 0):\n\n" +
            ComparisonMarkdown(r.comparison);
  if (!r.power.empty()) {
    report += "\nOver " + std::to_string(r.analyses.size()) + " replicates, share with p < " +
              FormatNumber(config.study.alpha) + ":\n";
    for (const auto& e : r.power) {
      report += "  " + e.id + ": " + std::to_string(e.significant) + " / " +
                std::to_string(e.replicates) + " = " + FormatNumber(e.power) + " [" +
                FormatNumber(e.conf_low) + ", " + FormatNumber(e.conf_high) + "]\n";
    }
  }
  return report;
}

// run.json's "seconds": CPU-side stage times summed over replicate 0's animators (they overlap in
// wall time), and the phases summed over the replicates.
nlohmann::json Timings(const StudyResults& r) {
  pipeline::StageSeconds stages;
  for (const auto& a : r.first.animators) {
    stages.perform += a.seconds.perform;
    stages.record += a.seconds.record;
    stages.annotate += a.seconds.annotate;
    stages.compose += a.seconds.compose;
    stages.metrics += a.seconds.metrics;
    stages.total += a.seconds.total;
  }
  return {{"animators", r.animator_seconds},
          {"animator_stages_replicate0",
           {{"perform", stages.perform},
            {"record", stages.record},
            {"annotate", stages.annotate},
            {"compose", stages.compose},
            {"metrics", stages.metrics},
            {"total", stages.total}}},
          {"scoring_and_analysis", r.scoring_seconds},
          {"rendered_frames", r.first.rendered_frames}};
}

}  // namespace

StudyResults RunStudyReplicates(const StudyConfig& config, const nlohmann::json& paper_reported,
                                const StudyRunProgress& progress) {
  const int replicates = config.study.replicates;
  StudyResults r;
  r.replicates_csv = ReplicatesCsvHeader();
  for (int i = 0; i < replicates; ++i) {
    SimulatedStudy s = RunSimulatedStudy(config.ForReplicate(i), i, [&](int done, int total) {
      if (progress) progress(i, done, total);
    });
    r.animator_seconds += s.animator_seconds;
    r.scoring_seconds += s.scoring_seconds;
    r.replicates_csv += ReplicateCsvRow(i, s.analysis);
    r.analyses.push_back(s.analysis);
    if (i == 0) {
      r.first = std::move(s);
    } else {
      s.animators.clear();
    }
  }
  const SimulatedStudy& s = r.first;
  r.figures = StudyFigures(s.data, s.analysis);
  r.comparison = CompareWithPaper(s.analysis, paper_reported, config.study.alpha, s.design.scorers);
  if (replicates > 1) {
    r.power = EstimatePower(r.analyses, config.study.alpha, config.study.analysis.conf_level);
  }
  r.report = ReportText(r, config);
  return r;
}

void WriteStudyFolder(const std::filesystem::path& out_dir, const StudyConfig& config,
                      const StudyResults& r, const StudyFolderOptions& options) {
  const SimulatedStudy& s = r.first;
  const int replicates = static_cast<int>(r.analyses.size());
  StagedFolder staged(out_dir);
  const std::filesystem::path& out = staged.staging();
  WriteStudyData(out, s.data);
  WriteFileAtomically(out / "results.json", ResultsJson(r, replicates).dump(2) + "\n");
  WriteFileAtomically(out / "tests.csv", s.analysis.TestsCsv());
  WriteFileAtomically(out / "take_scores.csv", s.analysis.TakeScoresCsv());
  WriteFileAtomically(out / "animator_scores.csv", s.analysis.AnimatorScoresCsv());
  WriteFileAtomically(out / "mean_ranks.csv", s.analysis.MeanRanksCsv());
  WriteFileAtomically(out / "animators.csv", AnimatorsCsv(s.animators));
  for (const auto& f : r.figures) {
    WriteFileAtomically(out / (f.name + ".svg"), f.svg);
    WriteFileAtomically(out / (f.name + ".csv"), f.csv);
  }
  WriteFileAtomically(out / "paper_comparison.md", ComparisonMarkdown(r.comparison));
  WriteFileAtomically(out / "paper_comparison.csv", ComparisonCsv(r.comparison));
  if (replicates > 1) {
    WriteFileAtomically(out / "replicates.csv", r.replicates_csv);
    WriteFileAtomically(out / "power.csv", PowerCsv(r.power));
  }
  if (!s.tracking_frames.empty()) {
    WriteFileAtomically(out / "tracking_errors.csv", pipeline::TakeFramesCsv(s.tracking_frames));
  }
  if (s.measured_error_model) {
    // The fit as pipeline/error_model.inc: copying it there makes it the fast mode's defaults.
    const std::string origin =
        "the full-fidelity study of " +
        (options.config_file.empty() ? std::string("the defaults") : options.config_file) + " (" +
        std::to_string(s.animators.size()) + " animators, population seed " +
        std::to_string(config.run.people.population.seed) + ") at commit " + options.git_commit +
        ".";
    WriteFileAtomically(out / "error_model.inc", s.measured_error_model->DefaultsSource(origin));
  }
  WriteFileAtomically(out / "report.txt", r.report);
  WriteFileAtomically(out / "config.resolved.json", config.ToJson().dump(2) + "\n");
  if (options.provenance) {
    WriteFileAtomically(out / "run.json", options.provenance(Timings(r)).dump(2) + "\n");
  }
  staged.Commit();
}

}  // namespace mmh::study
