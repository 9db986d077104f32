#include "report/sweep_data.h"

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/text_parsing.h"
#include "report/report_tables.h"
#include "sweep/aggregate.h"
#include "sweep/cell_store.h"
#include "sweep/plan.h"

namespace mmh::report {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kTables[] = {"results.csv", "summary.csv", "failures.csv",
                                   "variance_shares.csv"};

// How the spec gave an axis (grid values or a sampled range), for the plan's table.
std::string AxisKind(const sweep::Plan& plan, const sweep::AxisInfo& axis) {
  if (axis.sampled) {
    return std::string(plan.spec.samples.method == sweep::SampleMethod::kLatinHypercube
                           ? "Latin hypercube"
                           : "random") +
           (axis.scale == sweep::AxisScale::kLog ? " (log)" : "");
  }
  return axis.scale == sweep::AxisScale::kLog ? "grid (log)" : "grid";
}

// The distinct values of axis `a` over the plan's cells, in plan order (sampled axes: how many).
json AxisValues(const sweep::Plan& plan, std::size_t a) {
  std::vector<json> values;
  for (const sweep::Cell& cell : plan.cells) {
    const json& v = cell.params[a].second;
    if (std::find(values.begin(), values.end(), v) == values.end()) values.push_back(v);
  }
  if (plan.axes[a].sampled) return std::to_string(values.size()) + " sampled values";
  std::string text;
  for (const json& v : values) text += (text.empty() ? "" : ", ") + (v.is_string() ? v.get<std::string>() : v.dump());
  return text;
}

// The complete cells of results.csv with their metrics (the file as `mmh sweep aggregate` wrote
// it): rows matched to the plan's cells by id, metrics by the spec's names.
std::vector<sweep::ResultRow> ReadResults(const sweep::Plan& plan, const fs::path& dir) {
  const fs::path path = dir / "results.csv";
  const CsvTable table = ReadCsvTable(path);
  const int cell_column = ColumnOf(table, "cell", path);
  std::vector<int> metric_columns;
  for (const sweep::Metric& m : plan.spec.metrics) metric_columns.push_back(ColumnOf(table, m.name, path));
  std::map<std::string, int> index;
  for (std::size_t i = 0; i < plan.cells.size(); ++i) index[plan.cells[i].id] = static_cast<int>(i);
  std::vector<sweep::ResultRow> rows;
  for (std::size_t r = 0; r < table.rows.size(); ++r) {
    const std::string& id = table.rows[r][cell_column];
    const auto cell = index.find(id);
    if (cell == index.end()) {
      ThrowBadValue(path.string() + ":" + std::to_string(r + 2) + " cell", id, "a cell of plan.json");
    }
    sweep::ResultRow row{cell->second, {}};
    for (int column : metric_columns) row.metrics.push_back(NumberAt(table, r, column, path));
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace

json SweepData(const fs::path& dir) {
  const sweep::Plan plan = sweep::ReadPlan(dir);
  for (const char* table : kTables) {
    if (!fs::exists(dir / table)) {
      ThrowBadValue((dir / table).string(), "missing",
                    "the tables of `mmh sweep aggregate " + dir.string() + "` (run it first)");
    }
  }
  json data;
  const std::string command = sweep::CommandName(plan.spec.command);
  data["title"] = "Sweep of mmh " + command + ": " + std::to_string(plan.cells.size()) + " cells";

  // The plan and the state of its cells (status.json of each, as `mmh sweep status` reads it).
  int done = 0, failed = 0, missing = 0;
  for (const sweep::Cell& cell : plan.cells) {
    switch (sweep::ReadCellStatus(dir, cell.id).state) {
      case sweep::CellState::kComplete: ++done; break;
      case sweep::CellState::kFailed: ++failed; break;
      case sweep::CellState::kMissing: ++missing; break;
    }
  }
  json axes = json::array();
  for (std::size_t a = 0; a < plan.axes.size(); ++a) {
    axes.push_back({plan.axes[a].key, AxisKind(plan, plan.axes[a]), AxisValues(plan, a)});
  }
  json metrics = json::array();
  for (const sweep::Metric& m : plan.spec.metrics) metrics.push_back({m.name, m.file, m.key});
  data["sweep"] = {{"command", command},
                   {"description", plan.spec.description},
                   {"cells", plan.cells.size()},
                   {"points", plan.points},
                   {"replicates", plan.spec.replicates.count},
                   {"done", done},
                   {"failed", failed},
                   {"missing", missing},
                   {"mmh_version", plan.mmh_version}};
  data["tables"] = json::array();
  data["tables"].push_back({{"title", "Plan: axes"}, {"file", "plan.json"}, {"note", ""},
                            {"columns", {"axis", "kind", "values"}}, {"rows", axes}});
  data["tables"].push_back({{"title", "Plan: metrics"}, {"file", "plan.json"}, {"note", ""},
                            {"columns", {"metric", "file", "key"}}, {"rows", metrics}});

  // The aggregate as the sweep computes it now from its cells: when the files differ, they were
  // written before some cells finished (the page says so; the tables shown are the files).
  const sweep::Aggregate now = sweep::AggregateSweep(plan, dir);
  const bool current = now.results_csv == ReadTextFile(dir / "results.csv") &&
                       now.summary_csv == ReadTextFile(dir / "summary.csv") &&
                       now.failures_csv == ReadTextFile(dir / "failures.csv") &&
                       now.variance_csv == ReadTextFile(dir / "variance_shares.csv");
  data["sweep"]["aggregate_current"] = current;
  data["plots"] = json::array();
  for (const sweep::MetricAxisPlot& p : sweep::MetricAxisPlots(plan, ReadResults(plan, dir))) {
    json points = json::array();
    for (const sweep::LinePoint& q : p.plot.points) points.push_back({q.x, q.y, q.y_low, q.y_high});
    data["plots"].push_back({{"metric", p.plot.y_label}, {"axis", p.plot.x_label},
                             {"log_x", p.plot.log_x}, {"file", "plots/" + p.file},
                             {"points", points}});
  }
  // The aggregate's other figures (heat maps, variance shares) as it drew them.
  data["figures"] = json::array();
  std::vector<fs::path> svgs;
  if (fs::is_directory(dir / "plots")) {
    for (const auto& entry : fs::directory_iterator(dir / "plots")) {
      const std::string name = entry.path().filename().string();
      if (entry.path().extension() == ".svg" && name.find("_vs_") == std::string::npos) {
        svgs.push_back(entry.path());
      }
    }
  }
  std::sort(svgs.begin(), svgs.end());
  for (const fs::path& svg : svgs) {
    data["figures"].push_back({{"title", "plots/" + svg.filename().string()},
                               {"svg", InlineSvg(svg)}});
  }
  data["tables"].push_back(TableJson("Summary per parameter setting", dir / "summary.csv",
                                     "n cells and the spec's statistics over the replicates"));
  data["tables"].push_back(TableJson("Main-effect variance shares", dir / "variance_shares.csv",
                                     "eta squared of each axis (docs/sweeps.md)"));
  data["tables"].push_back(TableJson("Results", dir / "results.csv", "one row per complete cell"));
  data["tables"].push_back(TableJson("Failures", dir / "failures.csv",
                                     "exit code, signal and the tail of the errors"));
  return data;
}

}  // namespace mmh::report
