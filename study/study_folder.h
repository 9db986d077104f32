// `mmh study`'s work below the command line: the replicates of a simulated study
// (RunSimulatedStudy), what is derived from them (Figures 8-11, the comparison with the paper,
// each test's power), and its output folder, written whole or not at all. docs/study.md lists
// every file.
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "study/figures.h"
#include "study/paper_comparison.h"
#include "study/simulated_study.h"

namespace mmh::study {

struct StudyResults {
  SimulatedStudy first;                 // replicate 0, with its animators
  std::vector<StudyAnalysis> analyses;  // of every replicate (#replicates)
  std::string replicates_csv;           // replicates.csv: a row per replicate
  std::vector<Figure> figures;          // of replicate 0
  std::vector<ComparisonLine> comparison;  // replicate 0 beside the paper
  std::vector<PowerEstimate> power;        // with more than one replicate
  double animator_seconds = 0.0;           // phase 1, summed over the replicates
  double scoring_seconds = 0.0;            // phase 2 and the analysis, summed
  std::string report;                      // report.txt
};

// progress(replicate, animators done, animators) after each animator of each replicate.
using StudyRunProgress = std::function<void(int replicate, int done, int total)>;

// Runs config.study.replicates studies (replicate r with config.ForReplicate(r)) and compares
// replicate 0 with `paper_reported` (configs/paper_reported.json's content). Deterministic in the
// config; replicates after the first keep only their analysis.
StudyResults RunStudyReplicates(const StudyConfig& config, const nlohmann::json& paper_reported,
                                const StudyRunProgress& progress = {});

struct StudyFolderOptions {
  // Where the config came from and the source's commit, for error_model.inc's header ("" for
  // the defaults).
  std::string config_file;
  std::string git_commit;
  // run.json (the caller's provenance) for the study's timings.
  std::function<nlohmann::json(const nlohmann::json& timings)> provenance;
};

// Writes every file of the study into `out` through a staging folder renamed into place at the
// end (core/staged_folder.h): a kill while writing leaves no partial folder.
void WriteStudyFolder(const std::filesystem::path& out, const StudyConfig& config,
                      const StudyResults& results, const StudyFolderOptions& options);

}  // namespace mmh::study
