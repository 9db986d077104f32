// Gathering a sweep's results (DIR/results.csv, failures.csv, summary.csv, variance_shares.csv and
// plots/*.svg) from its cell folders. Everything is a function of the plan and the cells'
// outputs, so the tables are the same bytes whichever backend ran the cells.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "sweep/plan.h"
#include "sweep/plots.h"

namespace mmh::sweep {

// One row of results.csv: a complete cell and its metrics.
struct ResultRow {
  int cell = 0;  // index in the plan
  std::vector<double> metrics;  // spec.metrics order
};

struct Aggregate {
  std::vector<ResultRow> rows;
  int complete = 0;
  int failed = 0;  // including cells whose metric could not be read
  int missing = 0;
  std::string results_csv;
  std::string failures_csv;
  std::string summary_csv;
  std::string variance_csv;
  std::vector<std::pair<std::string, std::string>> plots;  // file name, SVG
};

// Reads every cell and computes the tables and plots (writes nothing).
Aggregate AggregateSweep(const Plan& plan, const std::filesystem::path& dir);

// A metric against a numeric axis as plots/<metric>_vs_<axis>.svg draws it: the mean of the rows
// at each of the axis's values (sampled axes: bins) over the other axes, with its 95 % CI.
struct MetricAxisPlot {
  int metric = 0;  // spec.metrics index
  int axis = 0;    // plan.axes index
  std::string file;  // the plot's name in plots/ (before WriteAggregate's character cleaning)
  LinePlot plot;
};
std::vector<MetricAxisPlot> MetricAxisPlots(const Plan& plan, const std::vector<ResultRow>& rows);

// Writes the tables into DIR and the plots into DIR/plots/ (each file atomically).
void WriteAggregate(const std::filesystem::path& dir, const Aggregate& aggregate);

// Mean, sample standard deviation and the 95 % confidence interval of the mean (Student's t,
// n - 1 degrees of freedom; NaN when n < 2).
struct MeanCi {
  int n = 0;
  double mean = 0, sd = 0, ci_low = 0, ci_high = 0, min = 0, max = 0, median = 0;
};
MeanCi Describe(std::vector<double> values);

// The share of the total sum of squares of `values` between the groups `group` (eta squared of a
// one-way layout, the main effect of that factor): 0..1.
double VarianceShare(const std::vector<double>& values, const std::vector<int>& group);

// A number as results.csv writes it (shortest round-trip form; "" for NaN).
std::string CsvNumber(double value);

}  // namespace mmh::sweep
