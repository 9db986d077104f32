#include "sweep/aggregate.h"

#include <algorithm>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_text.h"
#include "core/text_parsing.h"
#include "sweep/cell_store.h"
#include "sweep/plots.h"

namespace mmh::sweep {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string CsvText(const std::string& text) {
  bool quote = false;
  for (char c : text) quote = quote || c == ',' || c == '"' || c == '\n' || c == '\r';
  if (!quote) return text;
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string CsvValue(const json& value) {
  if (value.is_number()) return CsvNumber(value.get<double>());
  if (value.is_string()) return CsvText(value.get<std::string>());
  return CsvText(value.dump());
}

std::string ParamsHeader(const Plan& plan) {
  std::string header;
  for (const auto& axis : plan.axes) header += "," + CsvText(axis.key);
  return header;
}

std::string ParamsRow(const Cell& cell) {
  std::string row;
  for (const auto& [key, value] : cell.params) row += "," + CsvValue(value);
  return row;
}

// Groups of rows by the value of axis `a` (sampled axes: up to 5 bins of equal count, by value).
std::vector<int> GroupsOf(const Plan& plan, const std::vector<ResultRow>& rows, std::size_t a,
                          std::vector<std::string>* labels) {
  std::vector<int> group(rows.size());
  const AxisInfo& axis = plan.axes[a];
  if (!axis.sampled) {
    std::map<std::string, int> ids;
    for (std::size_t r = 0; r < rows.size(); ++r) {
      const json& v = plan.cells[rows[r].cell].params[a].second;
      const auto [it, inserted] = ids.emplace(v.dump(), static_cast<int>(ids.size()));
      if (inserted && labels) labels->push_back(v.is_string() ? v.get<std::string>() : v.dump());
      group[r] = it->second;
    }
    return group;
  }
  std::vector<std::size_t> order(rows.size());
  for (std::size_t r = 0; r < rows.size(); ++r) order[r] = r;
  auto value = [&](std::size_t r) {
    return plan.cells[rows[r].cell].params[a].second.get<double>();
  };
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t x, std::size_t y) { return value(x) < value(y); });
  const int bins = static_cast<int>(std::clamp<std::size_t>(rows.size() / 3, 1, 5));
  for (std::size_t k = 0; k < order.size(); ++k) {
    group[order[k]] = static_cast<int>(k * bins / order.size());
  }
  return group;
}

}  // namespace

std::string CsvNumber(double value) {
  if (std::isnan(value)) return "";
  return FormatNumber(value);
}

MeanCi Describe(std::vector<double> values) {
  MeanCi d;
  d.n = static_cast<int>(values.size());
  if (d.n == 0) {
    d.mean = d.sd = d.ci_low = d.ci_high = d.min = d.max = d.median = kNaN;
    return d;
  }
  double sum = 0;
  for (double v : values) sum += v;
  d.mean = sum / d.n;
  double ss = 0;
  for (double v : values) ss += (v - d.mean) * (v - d.mean);
  std::sort(values.begin(), values.end());
  d.min = values.front();
  d.max = values.back();
  d.median = d.n % 2 ? values[d.n / 2] : 0.5 * (values[d.n / 2 - 1] + values[d.n / 2]);
  if (d.n < 2) {
    d.sd = d.ci_low = d.ci_high = kNaN;
    return d;
  }
  d.sd = std::sqrt(ss / (d.n - 1));
  const boost::math::students_t t(d.n - 1);
  const double half = boost::math::quantile(t, 0.975) * d.sd / std::sqrt(d.n);
  d.ci_low = d.mean - half;
  d.ci_high = d.mean + half;
  return d;
}

double VarianceShare(const std::vector<double>& values, const std::vector<int>& group) {
  if (values.size() < 2) return kNaN;
  double mean = 0;
  for (double v : values) mean += v;
  mean /= values.size();
  std::map<int, std::pair<double, int>> sums;
  double total = 0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    sums[group[i]].first += values[i];
    sums[group[i]].second += 1;
    total += (values[i] - mean) * (values[i] - mean);
  }
  if (total <= 0) return 0.0;
  double between = 0;
  for (const auto& [g, s] : sums) {
    const double m = s.first / s.second;
    between += s.second * (m - mean) * (m - mean);
  }
  return std::clamp(between / total, 0.0, 1.0);
}

std::vector<MetricAxisPlot> MetricAxisPlots(const Plan& plan, const std::vector<ResultRow>& rows) {
  std::vector<MetricAxisPlot> plots;
  const auto& metrics = plan.spec.metrics;
  for (std::size_t m = 0; m < metrics.size(); ++m) {
    for (std::size_t x = 0; x < plan.axes.size(); ++x) {
      const AxisInfo& axis = plan.axes[x];
      if (!axis.numeric) continue;
      LinePlot plot;
      plot.title = metrics[m].name + " against " + axis.key;
      plot.x_label = axis.key;
      plot.y_label = metrics[m].name;
      plot.log_x = axis.scale == AxisScale::kLog;
      const std::vector<int> group = GroupsOf(plan, rows, x, nullptr);
      std::map<int, std::pair<std::vector<double>, std::vector<double>>> by_group;
      for (std::size_t r = 0; r < rows.size(); ++r) {
        by_group[group[r]].first.push_back(plan.cells[rows[r].cell].params[x].second.get<double>());
        by_group[group[r]].second.push_back(rows[r].metrics[m]);
      }
      for (const auto& [g, xy] : by_group) {
        const MeanCi dx = Describe(xy.first);
        const MeanCi dy = Describe(xy.second);
        plot.points.push_back({dx.mean, dy.mean, dy.ci_low, dy.ci_high});
      }
      std::sort(plot.points.begin(), plot.points.end(),
                [](const LinePoint& p, const LinePoint& q) { return p.x < q.x; });
      if (plot.points.size() < 2) continue;
      plots.push_back({static_cast<int>(m), static_cast<int>(x),
                       metrics[m].name + "_vs_" + axis.key + ".svg", std::move(plot)});
    }
  }
  return plots;
}

namespace {

// The cell's row prefix in results.csv and failures.csv: id, point, replicate, seed, parameters.
std::string CellPrefix(const Cell& cell) {
  return cell.id + "," + std::to_string(cell.point) + "," + std::to_string(cell.replicate) + "," +
         (cell.seed ? std::to_string(*cell.seed) : "") + ParamsRow(cell);
}

// Reads the metrics of the complete cell `cell` into `row` (spec.metrics order); the problem
// (a file missing or not JSON, a key absent or not a number) or "" when every metric was read.
std::string ReadCellMetrics(const Plan& plan, const fs::path& dir, const Cell& cell,
                            ResultRow* row) {
  std::map<std::string, json> files;
  for (const auto& m : plan.spec.metrics) {
    if (!files.count(m.file)) {
      const fs::path path = CellDir(dir, cell.id) / "out" / m.file;
      files[m.file] = json(json::value_t::discarded);
      try {
        if (fs::exists(path)) files[m.file] = ReadJsonFile(path);
      } catch (const InputError&) {
        // reported below as "missing or not JSON", with the cell
      }
    }
    const json& root = files[m.file];
    const json* value = root.is_discarded() ? nullptr : FindKey(root, m.key);
    if (!value || !(value->is_number() || value->is_boolean())) {
      return "metric '" + m.name + "': " +
             (root.is_discarded() ? "out/" + m.file + " is missing or not JSON"
                                  : "key '" + m.key + "' in out/" + m.file + " is " +
                                        (value ? "not a number: " + value->dump()
                                               : std::string("absent")));
    }
    row->metrics.push_back(value->is_boolean() ? (value->get<bool>() ? 1.0 : 0.0)
                                               : value->get<double>());
  }
  return "";
}

// Step 1: every cell's status and metrics: the rows, the counts, results.csv and failures.csv.
void GatherCells(const Plan& plan, const fs::path& dir, Aggregate* a) {
  std::string results = "cell,point,replicate,seed" + ParamsHeader(plan);
  for (const auto& m : plan.spec.metrics) results += "," + m.name;
  results += "\n";
  std::string failures = "cell,point,replicate,seed" + ParamsHeader(plan) +
                         ",exit_code,signal,message\n";
  for (std::size_t i = 0; i < plan.cells.size(); ++i) {
    const Cell& cell = plan.cells[i];
    const CellStatus status = ReadCellStatus(dir, cell.id);
    if (status.state == CellState::kMissing) {
      ++a->missing;
      continue;
    }
    std::string problem;
    ResultRow row{static_cast<int>(i), {}};
    if (status.state == CellState::kComplete) {
      problem = ReadCellMetrics(plan, dir, cell, &row);
    } else {
      problem = status.stderr_tail;
      for (char& c : problem) {
        if (c == '\n' || c == '\r') c = '|';
      }
    }
    if (!problem.empty()) {
      ++a->failed;
      failures += CellPrefix(cell) + "," + std::to_string(status.exit_code) + "," +
                  std::to_string(status.signal) + "," + CsvText(problem) + "\n";
      continue;
    }
    ++a->complete;
    results += CellPrefix(cell);
    for (double v : row.metrics) results += "," + CsvNumber(v);
    results += "\n";
    a->rows.push_back(std::move(row));
  }
  a->results_csv = results;
  a->failures_csv = failures;
}

// Step 2: summary.csv, per parameter setting over its replicates: n and each metric's chosen
// statistics.
std::string SummaryCsv(const Plan& plan, const std::vector<ResultRow>& result_rows) {
  const auto& metrics = plan.spec.metrics;
  std::string summary = "point" + ParamsHeader(plan) + ",n";
  for (const auto& m : metrics) {
    for (Statistic s : m.statistics) {
      if (s == Statistic::kCi95) {
        summary += "," + m.name + "_ci95_low," + m.name + "_ci95_high";
      } else {
        summary += "," + m.name + "_" + StatisticName(s);
      }
    }
  }
  summary += "\n";
  std::map<int, std::vector<const ResultRow*>> by_point;
  for (const auto& row : result_rows) by_point[plan.cells[row.cell].point].push_back(&row);
  for (const auto& [point, rows] : by_point) {
    summary += std::to_string(point) + ParamsRow(plan.cells[rows.front()->cell]) + "," +
               std::to_string(rows.size());
    for (std::size_t m = 0; m < metrics.size(); ++m) {
      std::vector<double> values;
      for (const auto* r : rows) values.push_back(r->metrics[m]);
      const MeanCi d = Describe(values);
      for (Statistic s : metrics[m].statistics) {
        switch (s) {
          case Statistic::kMean: summary += "," + CsvNumber(d.mean); break;
          case Statistic::kSd: summary += "," + CsvNumber(d.sd); break;
          case Statistic::kCi95:
            summary += "," + CsvNumber(d.ci_low) + "," + CsvNumber(d.ci_high);
            break;
          case Statistic::kMin: summary += "," + CsvNumber(d.min); break;
          case Statistic::kMax: summary += "," + CsvNumber(d.max); break;
          case Statistic::kMedian: summary += "," + CsvNumber(d.median); break;
        }
      }
    }
    summary += "\n";
  }
  return summary;
}

// Step 3: the main effects, the share of each metric's variance between the values of each axis:
// variance_shares.csv, and its bars in `bars`.
std::string VarianceSharesCsv(const Plan& plan, const std::vector<ResultRow>& rows,
                              std::vector<VarianceBar>* bars) {
  const auto& metrics = plan.spec.metrics;
  std::string variance = "metric,axis,share\n";
  for (std::size_t m = 0; m < metrics.size(); ++m) {
    std::vector<double> values;
    for (const auto& r : rows) values.push_back(r.metrics[m]);
    for (std::size_t x = 0; x < plan.axes.size(); ++x) {
      const double share = VarianceShare(values, GroupsOf(plan, rows, x, nullptr));
      variance += metrics[m].name + "," + CsvText(plan.axes[x].key) + "," + CsvNumber(share) + "\n";
      bars->push_back({metrics[m].name, plan.axes[x].key, share});
    }
  }
  return variance;
}

// The heat map of metric `m` (its mean per cell of the map) over the first two grid axes, if the
// plan has two.
std::optional<HeatMap> MetricHeatMap(const Plan& plan, const std::vector<ResultRow>& rows,
                                     std::size_t m) {
  std::vector<std::size_t> grid_axes;
  for (std::size_t x = 0; x < plan.axes.size(); ++x) {
    if (!plan.axes[x].sampled) grid_axes.push_back(x);
  }
  if (grid_axes.size() < 2) return std::nullopt;
  const std::string& name = plan.spec.metrics[m].name;
  const std::size_t ax = grid_axes[0], ay = grid_axes[1];
  HeatMap map;
  map.title = name + " (mean) over " + plan.axes[ax].key + " and " + plan.axes[ay].key;
  map.x_label = plan.axes[ax].key;
  map.y_label = plan.axes[ay].key;
  const std::vector<int> gx = GroupsOf(plan, rows, ax, &map.x_values);
  const std::vector<int> gy = GroupsOf(plan, rows, ay, &map.y_values);
  std::map<std::pair<int, int>, std::vector<double>> cells;
  for (std::size_t r = 0; r < rows.size(); ++r) cells[{gx[r], gy[r]}].push_back(rows[r].metrics[m]);
  map.values.assign(map.y_values.size(), std::vector<double>(map.x_values.size(), kNaN));
  for (const auto& [xy, v] : cells) map.values[xy.second][xy.first] = Describe(v).mean;
  return map;
}

// Step 4: the plots: the variance shares, then per metric its plots against each numeric axis and
// its heat map.
std::vector<std::pair<std::string, std::string>> Plots(const Plan& plan,
                                                       const std::vector<ResultRow>& rows,
                                                       const std::vector<VarianceBar>& bars) {
  std::vector<std::pair<std::string, std::string>> plots;
  plots.emplace_back("variance_shares.svg", VarianceSharesSvg(bars));
  const std::vector<MetricAxisPlot> line_plots = MetricAxisPlots(plan, rows);
  for (std::size_t m = 0; m < plan.spec.metrics.size(); ++m) {
    for (const MetricAxisPlot& p : line_plots) {
      if (p.metric == static_cast<int>(m)) plots.emplace_back(p.file, LinePlotSvg(p.plot));
    }
    if (const std::optional<HeatMap> map = MetricHeatMap(plan, rows, m)) {
      plots.emplace_back(plan.spec.metrics[m].name + "_heatmap.svg", HeatMapSvg(*map));
    }
  }
  return plots;
}

}  // namespace

Aggregate AggregateSweep(const Plan& plan, const fs::path& dir) {
  Aggregate a;
  GatherCells(plan, dir, &a);
  a.summary_csv = SummaryCsv(plan, a.rows);
  std::vector<VarianceBar> bars;
  a.variance_csv = VarianceSharesCsv(plan, a.rows, &bars);
  if (!a.rows.empty()) a.plots = Plots(plan, a.rows, bars);
  return a;
}

void WriteAggregate(const fs::path& dir, const Aggregate& aggregate) {
  WriteFileAtomically(dir / "results.csv", aggregate.results_csv);
  WriteFileAtomically(dir / "failures.csv", aggregate.failures_csv);
  WriteFileAtomically(dir / "summary.csv", aggregate.summary_csv);
  WriteFileAtomically(dir / "variance_shares.csv", aggregate.variance_csv);
  if (aggregate.plots.empty()) return;
  EnsureDirectory(dir / "plots");
  for (const auto& [name, svg] : aggregate.plots) {
    std::string file = name;
    for (char& c : file) {
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '-')) c = '_';
    }
    WriteFileAtomically(dir / "plots" / file, svg);
  }
}

}  // namespace mmh::sweep
