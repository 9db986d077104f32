// A small SVG bar chart writer for the study's figures (no plotting dependency): vertical bars,
// optional error bars, an optional horizontal reference line, y ticks at round steps, x labels
// (rotated when many), a legend of colours.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace mmh::study {

struct ChartBar {
  std::string label;            // x label ("" for none)
  double value = 0.0;           // bar height in data units
  std::optional<double> error;  // half-length of an error bar (e.g. one standard error)
  int series = 0;               // colour index (legend entry)
  double gap_before = 0.0;      // extra space before this bar, in bar widths (groups)
};

struct BarChart {
  std::string title;
  std::string x_label;
  std::string y_label;
  double y_min = 0.0;
  double y_max = 1.0;
  std::vector<ChartBar> bars;
  std::vector<std::string> series_names;  // legend (shown when more than one)
  std::optional<double> reference;        // a horizontal line at this value
  std::string reference_label;
  int width = 760;   // [px]
  int height = 400;  // [px]
};

// The chart as a standalone SVG document. Bars beyond [y_min, y_max] are clipped to it.
std::string BarChartSvg(const BarChart& chart);

// Round tick step for a span: 1, 2 or 5 times a power of ten, about `target` ticks.
double TickStep(double span, int target = 5);

// Escapes &, <, >, " for SVG text.
std::string EscapeXml(const std::string& text);

}  // namespace mmh::study
