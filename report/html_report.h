// `mmh report DIR`: one self-contained HTML file (DIR/report.html) of a compose, run, study, stats
// or sweep folder: scripts, styles, figures and the glTF inlined, no network at view time. The page's code
// is report/web/src (three.js and the figures), bundled at build time.
#pragma once

#include <filesystem>
#include <string>

namespace mmh::report {

enum class FolderKind {
  kCompose,  // mmh compose: montage.tum, timeline.csv, segments.csv, summary.json
  kRun,      // mmh run: montage/, takes/take_K/, metrics.json
  kStudy,    // mmh study: rankings.csv, comparisons.csv, figure8..11 .svg
  kStats,    // mmh stats: results.json, tests.csv, take_scores.csv, animator_scores.csv
  kSweep,    // mmh sweep (after mmh sweep aggregate): plan.json, cells/, results.csv, summary.csv
};

const char* FolderKindName(FolderKind kind);

// What kind of output `dir` is; InputError naming the folder and what each kind holds when it is
// none of them (or not a folder).
FolderKind DetectFolderKind(const std::filesystem::path& dir);

struct ReportOptions {
  // Largest side [cells] of each DTW matching-cost image (the reference and the source take are
  // sampled evenly down to it; the warps are drawn at full resolution over it).
  int dtw_image_size = 200;
  void Validate(const std::string& prefix) const;
};

struct ReportSummary {
  FolderKind kind = FolderKind::kCompose;
  std::filesystem::path file;  // DIR/report.html
  std::size_t bytes = 0;
  double seconds = 0.0;  // reading, building and writing
};

// The page for `dir` (everything read and checked first: a missing or malformed file is an
// InputError naming it).
std::string BuildReportHtml(const std::filesystem::path& dir, FolderKind kind,
                            const ReportOptions& options = {});

// Detects the kind, builds the page and writes DIR/report.html atomically.
ReportSummary WriteReport(const std::filesystem::path& dir, const ReportOptions& options = {});

}  // namespace mmh::report
