// Our simulated study's results beside the paper's (configs/paper_reported.json, as printed), one
// row per reported quantity, for paper_comparison.md / .csv of `mmh study`.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "study/study_analysis.h"

namespace mmh::study {

struct ComparisonLine {
  std::string quantity;  // e.g. "H1 t(df)"
  std::string paper;     // as printed ("5.18", "< 0.0001", "18 of 20")
  std::string ours;      // ours, formatted to the paper's precision or 4 significant digits
  // For tests: "yes" when ours reaches the same conclusion at `alpha` (significant or not) as the
  // paper; "no" when not; "" for descriptive quantities.
  std::string same_conclusion;
};

// `paper_reported`: the parsed configs/paper_reported.json. Throws InputError naming the check id
// when a needed entry is missing.
std::vector<ComparisonLine> CompareWithPaper(const StudyAnalysis& analysis,
                                             const nlohmann::json& paper_reported, double alpha,
                                             int scorers);

std::string ComparisonMarkdown(const std::vector<ComparisonLine>& lines);
std::string ComparisonCsv(const std::vector<ComparisonLine>& lines);

}  // namespace mmh::study
