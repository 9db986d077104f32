#include "report/html_report.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>

#include "core/annotation.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_text.h"
#include "core/text_parsing.h"
#include "core/tum_io.h"
#include "montage/match_cost.h"
#include "montage/blend.h"
#include "report/montage_clock.h"
#include "report/report_bundle.h"
#include "report/report_tables.h"
#include "report/sweep_data.h"

namespace mmh::report {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The name of the montage's node in montage.glb (MontageScene names it "<object> montage").
constexpr char kMontageNode[] = "proxy montage";

std::string Base64(const std::string& bytes) {
  static constexpr char kDigits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t a = static_cast<std::uint8_t>(bytes[i]);
    const std::uint32_t b = i + 1 < bytes.size() ? static_cast<std::uint8_t>(bytes[i + 1]) : 0;
    const std::uint32_t c = i + 2 < bytes.size() ? static_cast<std::uint8_t>(bytes[i + 2]) : 0;
    const std::uint32_t v = (a << 16) | (b << 8) | c;
    out += kDigits[(v >> 18) & 63];
    out += kDigits[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? kDigits[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kDigits[v & 63] : '=';
  }
  return out;
}

// JSON that may sit inside <script>: "</" would end the element.
std::string ScriptSafe(std::string text) {
  for (std::size_t at = text.find("</"); at != std::string::npos; at = text.find("</", at + 3)) {
    text.replace(at, 2, "<\\/");
  }
  return text;
}

std::string HtmlEscape(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else if (c == '"') out += "&quot;";
    else out += c;
  }
  return out;
}

// A take's path as written in summary.json: as given, relative to the working directory mmh
// compose ran in (run.json's working_directory), or in the folder.
fs::path ResolveInput(const std::string& given, const fs::path& dir, const std::string& what) {
  const fs::path path(given);
  if (fs::exists(path)) return path;
  if (path.is_relative()) {
    if (fs::exists(dir / "run.json")) {
      const json run = ReadJsonFile(dir / "run.json");
      if (run.contains("working_directory") && run["working_directory"].is_string()) {
        const fs::path there = fs::path(run["working_directory"].get<std::string>()) / path;
        if (fs::exists(there)) return there;
      }
    }
    if (fs::exists(dir / path.filename())) return dir / path.filename();
  }
  ThrowBadValue(what, given,
                "a readable file (the takes mmh compose read, as given, relative to run.json's "
                "working_directory, or copied into the folder)");
}

// Matching cost images (paper Figure 4), sampled evenly to at most size x size cells, as grey
// bytes (0 = the lowest cost of the image, darker is better), rows = source frames.
json DtwImage(const Trajectory& reference, const Trajectory& source, int take, double lambda,
              int size, double dtw_cost) {
  const int n = static_cast<int>(reference.size()), m = static_cast<int>(source.size());
  const int columns = std::min(n, size), rows = std::min(m, size);
  std::vector<double> cost(static_cast<std::size_t>(rows) * columns);
  for (int r = 0; r < rows; ++r) {
    const int s = rows > 1 ? static_cast<int>(std::lround(double(r) * (m - 1) / (rows - 1))) : 0;
    for (int c = 0; c < columns; ++c) {
      const int t = columns > 1 ? static_cast<int>(std::lround(double(c) * (n - 1) / (columns - 1))) : 0;
      cost[static_cast<std::size_t>(r) * columns + c] =
          montage::MatchCost(reference.poses[t], source.poses[s], lambda);
    }
  }
  const auto [lo, hi] = std::minmax_element(cost.begin(), cost.end());
  const double range = std::max(*hi - *lo, 1e-12);
  std::string bytes(cost.size(), '\0');
  for (std::size_t i = 0; i < cost.size(); ++i) {
    bytes[i] = static_cast<char>(std::lround(255.0 * (cost[i] - *lo) / range));
  }
  return {{"take", take}, {"size", {rows, columns}}, {"reference_frames", n},
          {"source_frames", m}, {"cost", Base64(bytes)}, {"dtw_cost", dtw_cost},
          {"cost_range", {*lo, *hi}}};
}

std::vector<double> Rounded(const std::vector<double>& values) {
  std::vector<double> out(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) out[i] = std::round(values[i] * 1000.0) / 1000.0;
  return out;
}

struct MontageFolder {
  fs::path dir;  // montage.tum, timeline.csv, segments.csv, summary.json, montage.glb
  std::vector<Trajectory> takes;
  std::vector<Annotation> annotations;
  std::vector<std::string> take_names;
  double lambda = 2.5;
  int reference_take = 0;
  std::vector<int> marker_frames;
};

// The data of a montage's page: timelines, segments, warps, DTW images, the glb.
json MontageData(const MontageFolder& folder, const ReportOptions& options, std::string* glb) {
  const fs::path& dir = folder.dir;
  const Trajectory montage = ReadTum(dir / "montage.tum");
  const fs::path timeline_path = dir / "timeline.csv";
  const CsvTable timeline = ReadCsvTable(timeline_path);
  const std::size_t m = folder.takes.size();
  if (timeline.columns.size() != 2 + 2 * m) {
    ThrowBadValue(timeline_path.string(), std::to_string(timeline.columns.size()) + " columns",
                  std::to_string(2 + 2 * m) + " for " + std::to_string(m) + " takes");
  }
  json data;
  std::vector<int> labels;
  std::vector<std::vector<int>> warps(m);
  std::vector<std::vector<double>> warped(m);
  const int take_column = ColumnOf(timeline, "take", timeline_path);
  for (std::size_t r = 0; r < timeline.rows.size(); ++r) {
    labels.push_back(static_cast<int>(NumberAt(timeline, r, take_column, timeline_path)));
    for (std::size_t l = 0; l < m; ++l) {
      const int w = static_cast<int>(NumberAt(timeline, r, 2 + l, timeline_path));
      if (w < 0 || w >= static_cast<int>(folder.takes[l].size())) {
        ThrowBadValue(timeline_path.string() + ":" + std::to_string(r + 2) + " warp_" +
                          std::to_string(l),
                      std::to_string(w), "a frame of " + folder.take_names[l]);
      }
      warps[l].push_back(w);
      warped[l].push_back(NumberAt(timeline, r, 2 + m + l, timeline_path));
    }
  }
  const std::size_t n = labels.size();
  if (n != folder.takes[folder.reference_take].size()) {
    ThrowBadValue(timeline_path.string(), std::to_string(n) + " reference frames",
                  std::to_string(folder.takes[folder.reference_take].size()) +
                      " (the frames of the reference take " +
                      folder.take_names[folder.reference_take] + ")");
  }
  const fs::path segments_path = dir / "segments.csv";
  const CsvTable segments = ReadCsvTable(segments_path);
  std::vector<montage::MontageSegment> played;
  for (std::size_t r = 0; r < segments.rows.size(); ++r) {
    json s;
    for (const char* key : {"take", "reference_first", "reference_last", "source_first",
                            "source_last", "montage_first", "montage_last"}) {
      s[key] = static_cast<int>(NumberAt(segments, r, ColumnOf(segments, key, segments_path),
                                         segments_path));
    }
    played.push_back({s["take"], s["reference_first"], s["reference_last"], s["source_first"],
                      s["source_last"], s["montage_first"], s["montage_last"]});
    data["segments"].push_back(s);
  }
  // Every take at its own frame for each montage frame (the 3D view's clocks).
  MontageClock clock;
  try {
    clock = ComputeMontageClock(played, warps);
  } catch (const InputError& e) {
    ThrowBadValue(segments_path.string(), e.what(), "the segments mmh wrote with timeline.csv");
  }
  if (clock.reference.size() != montage.size()) {
    ThrowBadValue(segments_path.string(), std::to_string(clock.reference.size()) + " montage frames",
                  std::to_string(montage.size()) + " (the frames of montage.tum)");
  }
  data["clock"] = {{"reference", clock.reference}, {"takes", clock.takes}};
  const json summary = ReadJsonFile(dir / "summary.json");
  std::vector<double> dtw_costs(m, std::nan(""));
  if (summary.contains("dtw_costs") && summary["dtw_costs"].size() == m) {
    dtw_costs = summary["dtw_costs"].get<std::vector<double>>();
  }
  for (std::size_t l = 0; l < m; ++l) {
    data["takes"].push_back({{"name", folder.take_names[l]},
                             {"frames", folder.takes[l].size()},
                             {"annotation", Rounded(folder.annotations[l].values)},
                             {"warp", warps[l]},
                             {"warped_annotation", Rounded(warped[l])}});
    data["dtw"].push_back(DtwImage(folder.takes[folder.reference_take], folder.takes[l],
                                   static_cast<int>(l), folder.lambda, options.dtw_image_size,
                                   dtw_costs[l]));
  }
  data["labels"] = labels;
  data["markers"] = folder.marker_frames;
  data["montage"] = {{"frames", montage.size()}, {"node", kMontageNode}};
  // The summary's numbers as a table.
  json rows = json::array();
  for (const auto& [key, value] : summary.items()) {
    if (value.is_number() || value.is_string() || value.is_boolean()) {
      rows.push_back({key, value.is_string() ? value.get<std::string>() : value.dump()});
    }
  }
  data["tables"].push_back({{"title", "Montage summary"}, {"file", "summary.json"},
                            {"columns", {"quantity", "value"}}, {"rows", rows}});
  if (fs::exists(dir / "montage.glb")) *glb = ReadBinaryFile(dir / "montage.glb");
  return data;
}

double LambdaOf(const fs::path& config_path, const char* section_key) {
  if (!fs::exists(config_path)) return 2.5;
  const json config = ReadJsonFile(config_path);
  const json::json_pointer pointer(std::string("/") + section_key + "/dtw/lambda");
  return config.contains(pointer) ? config.at(pointer).get<double>() : 2.5;
}

int ReferenceTakeOf(const fs::path& config_path) {
  if (!fs::exists(config_path)) return 0;
  const json config = ReadJsonFile(config_path);
  const json::json_pointer pointer("/montage/reference_take");
  return config.contains(pointer) ? config.at(pointer).get<int>() : 0;
}

json ComposeData(const fs::path& dir, const ReportOptions& options, std::string* glb) {
  MontageFolder folder;
  folder.dir = dir;
  const json summary = ReadJsonFile(dir / "summary.json");
  const std::string where = (dir / "summary.json").string();
  if (!summary.contains("take_files") || !summary.contains("annotation_files") ||
      summary["take_files"].size() != summary["annotation_files"].size() ||
      summary["take_files"].empty()) {
    ThrowBadValue(where, "no take_files / annotation_files of equal length",
                  "the summary mmh compose writes");
  }
  for (std::size_t l = 0; l < summary["take_files"].size(); ++l) {
    const std::string take = summary["take_files"][l];
    folder.takes.push_back(ReadTum(ResolveInput(take, dir, where + " take_files")));
    folder.annotations.push_back(ReadAnnotationCsv(
        ResolveInput(summary["annotation_files"][l], dir, where + " annotation_files")));
    folder.take_names.push_back(fs::path(take).stem().string());
  }
  folder.lambda = LambdaOf(dir / "config.resolved.json", "montage");
  folder.reference_take = ReferenceTakeOf(dir / "config.resolved.json");
  if (fs::exists(dir / "markers.tum")) {
    const Trajectory montage = ReadTum(dir / "montage.tum");
    for (double t : ReadTum(dir / "markers.tum").timestamps) {
      const auto it = std::lower_bound(montage.timestamps.begin(), montage.timestamps.end(), t - 1e-9);
      if (it == montage.timestamps.end() || std::abs(*it - t) > 1e-6) {
        ThrowBadValue((dir / "markers.tum").string(), "timestamp " + FormatNumber(t),
                      "a timestamp of montage.tum");
      }
      folder.marker_frames.push_back(static_cast<int>(it - montage.timestamps.begin()));
    }
  }
  json data = MontageData(folder, options, glb);
  data["title"] = "Montage of " + std::to_string(folder.takes.size()) + " takes";
  // Layered objects (mmh compose --layer-takes): composed without time warping, each in
  // layers/NAME/; the 3D view plays them beside the first object.
  if (summary.contains("layers")) {
    for (const json& layer : summary["layers"]) {
      const std::string name = layer.value("name", "");
      const fs::path layer_dir = dir / "layers" / name;
      const json layer_summary = ReadJsonFile(layer_dir / "summary.json");
      data["tables"].push_back(TableJson(
          "Layered object " + name + ": segments", layer_dir / "segments.csv",
          std::to_string(layer_summary.value("takes", 0)) + " takes composed without time "
          "warping; total cost " + layer_summary.value("total_cost", json()).dump() +
          (layer_summary.contains("warnings") && !layer_summary["warnings"].empty()
               ? "; warnings: " + layer_summary["warnings"].dump()
               : "")));
    }
    data["title"] = data["title"].get<std::string>() + " and " +
                    std::to_string(summary["layers"].size()) +
                    (summary["layers"].size() == 1 ? " layered object" : " layered objects");
  }
  return data;
}

json RunData(const fs::path& dir, const ReportOptions& options, std::string* glb) {
  MontageFolder folder;
  folder.dir = dir / "montage";
  std::vector<std::pair<int, fs::path>> takes;
  const std::regex take_name("take_([0-9]+)");
  for (const auto& entry : fs::directory_iterator(dir / "takes")) {
    std::smatch match;
    const std::string name = entry.path().filename().string();
    if (entry.is_directory() && std::regex_match(name, match, take_name)) {
      takes.emplace_back(std::stoi(match[1]), entry.path());
    }
  }
  std::sort(takes.begin(), takes.end());
  for (const auto& [index, path] : takes) {
    folder.takes.push_back(ReadTum(path / "tracked.tum"));
    folder.annotations.push_back(ReadAnnotationCsv(path / "read_annotation.csv"));
    folder.take_names.push_back("take " + std::to_string(index + 1));
  }
  if (folder.takes.empty()) {
    ThrowBadValue((dir / "takes").string(), "no take_K folders", "the takes of mmh run");
  }
  folder.lambda = LambdaOf(dir / "config.resolved.json", "montage");
  folder.reference_take = ReferenceTakeOf(dir / "config.resolved.json");
  json data = MontageData(folder, options, glb);
  data["title"] = "One animator's run: montage of " + std::to_string(folder.takes.size()) +
                  " tracked takes";
  if (fs::exists(dir / "metrics.csv")) {
    data["tables"].push_back(TableJson("Metrics", dir / "metrics.csv",
                                       "metrics.json flattened (docs/pipeline.md)"));
  }
  return data;
}

json StudyData(const fs::path& dir) {
  json data;
  data["title"] = "Simulated user study";
  const std::vector<std::pair<std::string, std::string>> figures = {
      {"figure8_mean_ranks", "Figure 8: mean rank of each take and the montage (animators)"},
      {"figure9_take_scores", "Figure 9: probability that the montage is better than a take"},
      {"figure10_all_takes", "Figure 10: probability that the montage is better than all takes"},
      {"figure11_take_order", "Figure 11: probability that the montage is better, by take order"}};
  data["figures"] = json::array();
  for (const auto& [name, title] : figures) {
    const fs::path path = dir / (name + ".svg");
    if (!fs::exists(path)) continue;
    data["figures"].push_back({{"title", title}, {"svg", InlineSvg(path)}});
  }
  data["tables"] = json::array();
  data["tables"].push_back(TableJson("The tests", dir / "tests.csv", "docs/statistics.md"));
  if (fs::exists(dir / "paper_comparison.csv")) {
    data["tables"].push_back(TableJson("Beside the paper", dir / "paper_comparison.csv",
                                       "configs/paper_reported.json"));
  }
  if (fs::exists(dir / "power.csv")) {
    data["tables"].push_back(TableJson("Power", dir / "power.csv",
                                       "share of replicates with p < alpha, Clopper-Pearson 95 %"));
  }
  data["tables"].push_back(TableJson("Mean ranks", dir / "mean_ranks.csv"));
  if (fs::exists(dir / "report.txt")) {
    data["texts"].push_back({{"title", "report.txt"}, {"text", ReadTextFile(dir / "report.txt")}});
  }
  return data;
}

// mmh stats's folder: the tests, the scores and the analysis's text (docs/statistics.md).
json StatsData(const fs::path& dir) {
  json data;
  data["title"] = "Statistics of study data (mmh stats)";
  data["tables"] = json::array();
  data["tables"].push_back(TableJson("The tests", dir / "tests.csv", "docs/statistics.md"));
  data["tables"].push_back(TableJson("Take scores", dir / "take_scores.csv",
                                     "m_ij per take (Figures 9 and 11)"));
  data["tables"].push_back(TableJson("Animator scores", dir / "animator_scores.csv"));
  if (fs::exists(dir / "mean_ranks.csv")) {
    data["tables"].push_back(TableJson("Mean ranks", dir / "mean_ranks.csv"));
  }
  if (fs::exists(dir / "report.txt")) {
    data["texts"].push_back({{"title", "report.txt"}, {"text", ReadTextFile(dir / "report.txt")}});
  }
  return data;
}

}  // namespace

const char* FolderKindName(FolderKind kind) {
  switch (kind) {
    case FolderKind::kCompose: return "compose";
    case FolderKind::kRun: return "run";
    case FolderKind::kStudy: return "study";
    case FolderKind::kStats: return "stats";
    case FolderKind::kSweep: return "sweep";
  }
  return "?";
}

void ReportOptions::Validate(const std::string& prefix) const {
  if (dtw_image_size < 2 || dtw_image_size > 2000) {
    ThrowBadValue(prefix + "dtw_image_size", std::to_string(dtw_image_size), "2..2000 cells");
  }
}

FolderKind DetectFolderKind(const fs::path& dir) {
  const auto has = [&](const char* name) { return fs::exists(dir / name); };
  if (!fs::is_directory(dir)) ThrowBadValue(dir.string(), "not a folder", "an output folder of mmh");
  if (has("montage/montage.tum") && has("takes") && has("metrics.json")) return FolderKind::kRun;
  if (has("montage.tum") && has("timeline.csv") && has("segments.csv") && has("summary.json")) {
    return FolderKind::kCompose;
  }
  if (has("rankings.csv") && has("comparisons.csv") && has("tests.csv")) return FolderKind::kStudy;
  if (has("results.json") && has("tests.csv") && has("take_scores.csv") &&
      has("animator_scores.csv")) {
    return FolderKind::kStats;
  }
  if (has("plan.json") && has("configs")) return FolderKind::kSweep;
  ThrowBadValue(dir.string(), "a folder of another kind",
                "the output of mmh compose (montage.tum, timeline.csv, segments.csv, "
                "summary.json), mmh run (montage/, takes/, metrics.json), mmh study "
                "(rankings.csv, comparisons.csv, tests.csv), mmh stats (results.json, tests.csv, "
                "take_scores.csv, animator_scores.csv) or mmh sweep (plan.json, configs/; "
                "results.csv, summary.csv, failures.csv, variance_shares.csv after mmh sweep "
                "aggregate)");
}

std::string BuildReportHtml(const fs::path& dir, FolderKind kind, const ReportOptions& options) {
  options.Validate("report.");
  std::string glb;
  json data;
  switch (kind) {
    case FolderKind::kCompose: data = ComposeData(dir, options, &glb); break;
    case FolderKind::kRun: data = RunData(dir, options, &glb); break;
    case FolderKind::kStudy: data = StudyData(dir); break;
    case FolderKind::kStats: data = StatsData(dir); break;
    case FolderKind::kSweep: data = SweepData(dir); break;
  }
  data["kind"] = FolderKindName(kind);
  data["folder"] = fs::absolute(dir).lexically_normal().string();
  const std::string title = data["title"];
  std::string html;
  html += "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  html += "<meta name=\"generator\" content=\"mmh report\">\n";
  html += "<title>" + HtmlEscape(title) + " - mmh</title>\n<style>\n";
  html += internal::JoinChunks(internal::kReportStyleChunks);
  html += "</style>\n</head>\n<body>\n<div id=\"app\"></div>\n";
  html += "<script type=\"application/json\" id=\"mmh-data\">" + ScriptSafe(data.dump()) +
          "</script>\n";
  if (!glb.empty()) {
    html += "<script type=\"application/octet-stream\" id=\"mmh-glb\">" + Base64(glb) +
            "</script>\n";
  }
  html += "<script>\n" + ScriptSafe(internal::JoinChunks(internal::kReportScriptChunks)) +
          "\n</script>\n</body>\n</html>\n";
  return html;
}

ReportSummary WriteReport(const fs::path& dir, const ReportOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  ReportSummary summary;
  summary.kind = DetectFolderKind(dir);
  const std::string html = BuildReportHtml(dir, summary.kind, options);
  summary.file = dir / "report.html";
  WriteFileAtomically(summary.file, html);
  summary.bytes = html.size();
  summary.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace mmh::report
