// The user-study data as CSV files (docs/statistics.md, "Input files"): what `mmh stats` reads and
// what the simulated study writes. A study folder holds
//
//   rankings.csv       animator,item,rank
//                      each animator ranks the same items (take1..takeK and montage), 1 = best
//   comparisons.csv    scorer,animator,take,montage_preferred
//                      one binary comparison per row: did the scorer prefer the animator's montage
//                      (1) or the take shown (0)
//   segment_costs.csv  animator,cost_unconstrained,cost_constrained,short_segments_unconstrained
//                      [,reference_frames]
//                      (optional) the montage cost without and with the Segment Length Constraint
//
// Readers check everything and throw InputError naming the file, line, column, value and
// expectation; writers produce exactly what the readers accept.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace mmh::study {

inline constexpr const char* kRankingsFile = "rankings.csv";
inline constexpr const char* kComparisonsFile = "comparisons.csv";
inline constexpr const char* kSegmentCostsFile = "segment_costs.csv";
// The item name of the montage in rankings.csv; takes are "take1", "take2", ...
inline constexpr const char* kMontageItem = "montage";

struct RankingRow {
  std::string animator;  // animator ID (no commas, quotes or surrounding blanks)
  std::string item;      // "montage" or "take<k>", k >= 1 the recording order
  double rank = 0.0;     // 1 = best; a permutation of 1..#items per animator (mid-ranks if allowed)
  int line = 0;          // line in the file (0 when made in memory)
};

struct ComparisonRow {
  std::string scorer;
  std::string animator;
  int take = 0;  // take number, 1..K in recording order
  bool montage_preferred = false;
  int line = 0;
};

struct SegmentCostRow {
  std::string animator;
  double cost_unconstrained = 0.0;       // C_T of the optimum without the constraint (d = 0)
  double cost_constrained = 0.0;         // C_T with the Segment Length Constraint (d = 60)
  int short_segments_unconstrained = 0;  // segments of the unconstrained optimum not longer than d
  // n, frames of the reference timeline the labelling ran on (optional column; 0 = not given).
  // With it the analysis puts the increase on the paper's scale (study/study_analysis.h).
  int reference_frames = 0;
  int line = 0;
};

struct StudyData {
  std::vector<RankingRow> rankings;
  std::vector<ComparisonRow> comparisons;
  std::vector<SegmentCostRow> segment_costs;  // empty: no segment_costs.csv
  // Where the rows came from, for messages ("DIR/rankings.csv"; "rankings" when made in memory).
  std::string rankings_source = "rankings";
  std::string comparisons_source = "comparisons";
  std::string segment_costs_source = "segment_costs";
};

struct StudyDataOptions {
  // Accept tied ranks given as mid-ranks (e.g. 1, 2.5, 2.5, 4); otherwise the ranks of every
  // animator must be a permutation of 1..#items.
  bool allow_tied_ranks = false;

  template <class V>
  void VisitFields(V& v) {
    v("allow_tied_ranks", allow_tied_ranks);
  }
  void Validate(const std::string& /*prefix*/) const {}  // nothing to check
};

// Reads rankings.csv and comparisons.csv (required) and segment_costs.csv (optional) from `dir`,
// then ValidateStudyData.
StudyData ReadStudyData(const std::filesystem::path& dir, const StudyDataOptions& options = {});

// The consistency rules of docs/statistics.md: unique (animator, item) and (scorer, animator,
// take); every animator ranks the same items, with ranks a permutation of 1..#items (or valid
// mid-ranks); take numbers 1..K all present among the comparisons; costs finite (negative allowed:
// the compositor's data cost is -a'), constrained >= unconstrained; at most one cost row per
// animator. Throws InputError naming source and line.
void ValidateStudyData(const StudyData& data, const StudyDataOptions& options = {});

// The CSV text of each file (header and one line per row, numbers in shortest round-trip form).
std::string RankingsToCsv(const std::vector<RankingRow>& rows);
std::string ComparisonsToCsv(const std::vector<ComparisonRow>& rows);
std::string SegmentCostsToCsv(const std::vector<SegmentCostRow>& rows);

// Writes the files of `data` into `dir` (created if needed; each file written atomically;
// segment_costs.csv only when there are cost rows).
void WriteStudyData(const std::filesystem::path& dir, const StudyData& data);

// "take<k>" -> k, or 0 when `item` is not a take name.
int TakeNumberOfItem(const std::string& item);

}  // namespace mmh::study
