#include "sweep/plots.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

#include "core/error.h"
#include "study/svg_chart.h"

namespace mmh::sweep {
namespace {

using study::EscapeXml;

std::string Num(double v) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.2f", v);
  return text;
}

std::string Label(double v) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.4g", v);
  return text;
}

std::string Header(int width, int height, const std::string& title) {
  return "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(width) +
         "\" height=\"" + std::to_string(height) + "\" viewBox=\"0 0 " + std::to_string(width) +
         " " + std::to_string(height) +
         "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" "
         "fill=\"white\"/>\n<text x=\"" +
         std::to_string(width / 2) + "\" y=\"20\" text-anchor=\"middle\" font-size=\"14\">" +
         EscapeXml(title) + "</text>\n";
}

// A colour on a blue-yellow ramp for u in [0, 1].
std::string Ramp(double u) {
  u = std::clamp(u, 0.0, 1.0);
  const double stops[3][3] = {{68, 1, 84}, {33, 145, 140}, {253, 231, 37}};  // viridis ends, mid
  const double s = u * 2;
  const int k = std::min(1, static_cast<int>(s));
  const double f = s - k;
  char text[16];
  std::snprintf(text, sizeof(text), "#%02x%02x%02x",
                static_cast<int>(std::lround(stops[k][0] + f * (stops[k + 1][0] - stops[k][0]))),
                static_cast<int>(std::lround(stops[k][1] + f * (stops[k + 1][1] - stops[k][1]))),
                static_cast<int>(std::lround(stops[k][2] + f * (stops[k + 1][2] - stops[k][2]))));
  return text;
}

}  // namespace

std::string LinePlotSvg(const LinePlot& plot) {
  const int width = 640, height = 400, left = 70, right = 20, top = 36, bottom = 56;
  auto tx = [&](double x) { return plot.log_x ? std::log10(x) : x; };
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const auto& p : plot.points) {
    x0 = std::min(x0, tx(p.x));
    x1 = std::max(x1, tx(p.x));
    for (double y : {p.y, p.y_low, p.y_high}) {
      if (std::isfinite(y)) {
        y0 = std::min(y0, y);
        y1 = std::max(y1, y);
      }
    }
  }
  if (x1 <= x0) x1 = x0 + 1;
  if (y1 <= y0) {
    y0 -= 0.5;
    y1 += 0.5;
  }
  const double pad = 0.05 * (y1 - y0);
  y0 -= pad;
  y1 += pad;
  auto px = [&](double x) { return left + (tx(x) - x0) / (x1 - x0) * (width - left - right); };
  auto py = [&](double y) { return height - bottom - (y - y0) / (y1 - y0) * (height - top - bottom); };
  std::string svg = Header(width, height, plot.title);
  // Axes and ticks.
  svg += "<line x1=\"" + Num(left) + "\" y1=\"" + Num(height - bottom) + "\" x2=\"" +
         Num(width - right) + "\" y2=\"" + Num(height - bottom) + "\" stroke=\"black\"/>\n";
  svg += "<line x1=\"" + Num(left) + "\" y1=\"" + Num(top) + "\" x2=\"" + Num(left) + "\" y2=\"" +
         Num(height - bottom) + "\" stroke=\"black\"/>\n";
  const double ystep = study::TickStep(y1 - y0);
  for (double y = std::ceil(y0 / ystep) * ystep; y <= y1 + 1e-12 * std::abs(y1); y += ystep) {
    svg += "<text x=\"" + Num(left - 6) + "\" y=\"" + Num(py(y) + 4) +
           "\" text-anchor=\"end\">" + Label(std::abs(y) < 1e-12 * ystep ? 0.0 : y) + "</text>\n";
    svg += "<line x1=\"" + Num(left) + "\" y1=\"" + Num(py(y)) + "\" x2=\"" + Num(width - right) +
           "\" y2=\"" + Num(py(y)) + "\" stroke=\"#eee\"/>\n";
  }
  for (const auto& p : plot.points) {
    svg += "<text x=\"" + Num(px(p.x)) + "\" y=\"" + Num(height - bottom + 16) +
           "\" text-anchor=\"middle\">" + Label(p.x) + "</text>\n";
  }
  svg += "<text x=\"" + Num((left + width - right) / 2.0) + "\" y=\"" + Num(height - 12) +
         "\" text-anchor=\"middle\">" + EscapeXml(plot.x_label) +
         (plot.log_x ? " (log scale)" : "") + "</text>\n";
  svg += "<text transform=\"translate(16," + Num((top + height - bottom) / 2.0) +
         ") rotate(-90)\" text-anchor=\"middle\">" + EscapeXml(plot.y_label) + "</text>\n";
  // The 95 % CI band where every point has one.
  bool band = true;
  for (const auto& p : plot.points) band = band && std::isfinite(p.y_low) && std::isfinite(p.y_high);
  if (band) {
    std::string path;
    for (const auto& p : plot.points) {
      path += (path.empty() ? "M" : " L") + Num(px(p.x)) + "," + Num(py(p.y_high));
    }
    for (auto it = plot.points.rbegin(); it != plot.points.rend(); ++it) {
      path += " L" + Num(px(it->x)) + "," + Num(py(it->y_low));
    }
    svg += "<path d=\"" + path + " Z\" fill=\"#4c78a8\" fill-opacity=\"0.25\" stroke=\"none\">"
           "<title>95 % confidence interval of the mean</title></path>\n";
  }
  std::string line;
  for (const auto& p : plot.points) {
    line += (line.empty() ? "" : " ") + Num(px(p.x)) + "," + Num(py(p.y));
  }
  svg += "<polyline points=\"" + line + "\" fill=\"none\" stroke=\"#4c78a8\" stroke-width=\"2\"/>\n";
  for (const auto& p : plot.points) {
    svg += "<circle cx=\"" + Num(px(p.x)) + "\" cy=\"" + Num(py(p.y)) +
           "\" r=\"3\" fill=\"#4c78a8\"><title>" + Label(p.x) + ": " + Label(p.y) +
           "</title></circle>\n";
  }
  svg += "<text x=\"" + Num(width - right) + "\" y=\"" + Num(top - 4) +
         "\" text-anchor=\"end\" fill=\"#666\">mean" + std::string(band ? " and 95 % CI" : "") +
         "</text>\n</svg>\n";
  return svg;
}

std::string HeatMapSvg(const HeatMap& map) {
  const int cols = static_cast<int>(map.x_values.size());
  const int rows = static_cast<int>(map.y_values.size());
  const int cell_w = std::clamp(520 / std::max(1, cols), 24, 90);
  const int cell_h = std::clamp(320 / std::max(1, rows), 18, 60);
  const int left = 90, top = 40, bottom = 60, legend = 90;
  const int width = left + cols * cell_w + legend, height = top + rows * cell_h + bottom;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& row : map.values) {
    for (double v : row) {
      if (std::isfinite(v)) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
    }
  }
  std::string svg = Header(width, height, map.title);
  for (int r = 0; r < rows; ++r) {
    // Row 0 at the bottom (y grows upwards).
    const int y = top + (rows - 1 - r) * cell_h;
    svg += "<text x=\"" + Num(left - 6) + "\" y=\"" + Num(y + cell_h / 2.0 + 4) +
           "\" text-anchor=\"end\">" + EscapeXml(map.y_values[r]) + "</text>\n";
    for (int c = 0; c < cols; ++c) {
      const double v = map.values[r][c];
      const std::string fill =
          std::isfinite(v) ? Ramp(hi > lo ? (v - lo) / (hi - lo) : 0.5) : std::string("#ddd");
      svg += "<rect x=\"" + std::to_string(left + c * cell_w) + "\" y=\"" + std::to_string(y) +
             "\" width=\"" + std::to_string(cell_w) + "\" height=\"" + std::to_string(cell_h) +
             "\" fill=\"" + fill + "\" stroke=\"white\"><title>" +
             EscapeXml(map.x_values[c] + ", " + map.y_values[r]) + ": " +
             (std::isfinite(v) ? Label(v) : "no data") + "</title></rect>\n";
    }
  }
  for (int c = 0; c < cols; ++c) {
    svg += "<text x=\"" + Num(left + (c + 0.5) * cell_w) + "\" y=\"" +
           Num(top + rows * cell_h + 16) + "\" text-anchor=\"middle\">" +
           EscapeXml(map.x_values[c]) + "</text>\n";
  }
  svg += "<text x=\"" + Num(left + cols * cell_w / 2.0) + "\" y=\"" + Num(height - 14) +
         "\" text-anchor=\"middle\">" + EscapeXml(map.x_label) + "</text>\n";
  svg += "<text transform=\"translate(16," + Num(top + rows * cell_h / 2.0) +
         ") rotate(-90)\" text-anchor=\"middle\">" + EscapeXml(map.y_label) + "</text>\n";
  // Legend: the ramp with its ends.
  const int lx = left + cols * cell_w + 20;
  for (int k = 0; k < 20; ++k) {
    svg += "<rect x=\"" + std::to_string(lx) + "\" y=\"" +
           Num(top + (19 - k) * rows * cell_h / 20.0) + "\" width=\"16\" height=\"" +
           Num(rows * cell_h / 20.0 + 0.5) + "\" fill=\"" + Ramp(k / 19.0) + "\"/>\n";
  }
  if (std::isfinite(lo)) {
    svg += "<text x=\"" + std::to_string(lx + 20) + "\" y=\"" + Num(top + 10) + "\">" + Label(hi) +
           "</text>\n<text x=\"" + std::to_string(lx + 20) + "\" y=\"" +
           Num(top + rows * cell_h) + "\">" + Label(lo) + "</text>\n";
  }
  return svg + "</svg>\n";
}

std::string VarianceSharesSvg(const std::vector<VarianceBar>& bars) {
  study::BarChart chart;
  chart.title = "Share of each metric's variance explained by each axis (main effects)";
  chart.x_label = "metric";
  chart.y_label = "share of variance";
  chart.y_min = 0;
  chart.y_max = 1;
  std::map<std::string, int> series;
  for (const auto& b : bars) {
    if (series.emplace(b.axis, static_cast<int>(series.size())).second) {
      chart.series_names.push_back(b.axis);
    }
  }
  std::string last_metric;
  for (const auto& b : bars) {
    const bool first = b.metric != last_metric;
    chart.bars.push_back({first ? b.metric : "", std::isfinite(b.share) ? b.share : 0.0,
                          std::nullopt, series[b.axis], first && !last_metric.empty() ? 1.0 : 0.0});
    last_metric = b.metric;
  }
  chart.width = std::max(760, 40 + 26 * static_cast<int>(bars.size()));
  return study::BarChartSvg(chart);
}

}  // namespace mmh::sweep
