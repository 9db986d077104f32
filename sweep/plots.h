// The sweep's SVG plots (no plotting dependency): a metric against a numeric axis with its 95 %
// confidence band, a heat map over two axes, and the main-effect variance shares (a bar chart
// from study/svg_chart).
#pragma once

#include <string>
#include <vector>

namespace mmh::sweep {

struct LinePoint {
  double x = 0, y = 0;
  double y_low = 0, y_high = 0;  // the CI band (NaN: none)
};

struct LinePlot {
  std::string title, x_label, y_label;
  bool log_x = false;
  std::vector<LinePoint> points;  // by increasing x
};

struct HeatMap {
  std::string title, x_label, y_label;
  std::vector<std::string> x_values, y_values;  // column and row labels
  std::vector<std::vector<double>> values;      // [row][column], NaN = no data
};

struct VarianceBar {
  std::string metric, axis;
  double share = 0;  // 0..1
};

std::string LinePlotSvg(const LinePlot& plot);
std::string HeatMapSvg(const HeatMap& map);
std::string VarianceSharesSvg(const std::vector<VarianceBar>& bars);

}  // namespace mmh::sweep
