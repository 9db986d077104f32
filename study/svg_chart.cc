#include "study/svg_chart.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/error.h"

namespace mmh::study {
namespace {

// Colour-blind-safe palette (Okabe & Ito 2008).
constexpr const char* kColours[] = {"#0072B2", "#E69F00", "#009E73", "#CC79A7",
                                    "#56B4E9", "#D55E00", "#F0E442", "#000000"};

std::string Fixed(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

// Decimals that show a tick step exactly (0.25 -> 2, 5 -> 0).
int DecimalsOf(double step) {
  int decimals = 0;
  while (decimals < 6 && std::abs(step * std::pow(10, decimals) -
                                  std::round(step * std::pow(10, decimals))) > 1e-9) {
    ++decimals;
  }
  return decimals;
}

}  // namespace

std::string EscapeXml(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

double TickStep(double span, int target) {
  if (!(span > 0) || !std::isfinite(span)) return 1.0;
  const double raw = span / std::max(1, target);
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * power >= raw * 0.999) return m * power;
  }
  return 10 * power;
}

std::string BarChartSvg(const BarChart& chart) {
  if (!(chart.y_max > chart.y_min) || !std::isfinite(chart.y_min) || !std::isfinite(chart.y_max)) {
    ThrowBadValue("chart '" + chart.title + "' y range",
                  FormatNumber(chart.y_min) + " .. " + FormatNumber(chart.y_max),
                  "finite bounds with y_min < y_max");
  }
  const bool rotate = chart.bars.size() > 12;
  const double left = 70, right = 20, top = 40;
  const double bottom = rotate ? 90 : 60;
  const double plot_w = chart.width - left - right;
  const double plot_h = chart.height - top - bottom;
  const auto y_of = [&](double v) {
    const double c = std::clamp(v, chart.y_min, chart.y_max);
    return top + plot_h * (chart.y_max - c) / (chart.y_max - chart.y_min);
  };
  double units = 0;  // bar widths incl. gaps: each bar 1, spacing 0.25
  for (const auto& bar : chart.bars) units += 1.25 + bar.gap_before;
  units += 0.25;
  const double unit = chart.bars.empty() ? 0 : plot_w / units;

  std::ostringstream svg;
  svg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << chart.width << "\" height=\""
      << chart.height << "\" viewBox=\"0 0 " << chart.width << ' ' << chart.height
      << "\" font-family=\"Helvetica, Arial, sans-serif\" font-size=\"12\">\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
      << "<text x=\"" << chart.width / 2 << "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">"
      << EscapeXml(chart.title) << "</text>\n";
  // Y axis, ticks and grid.
  const double step = TickStep(chart.y_max - chart.y_min);
  const int decimals = DecimalsOf(step);
  for (double v = std::ceil(chart.y_min / step - 1e-9) * step; v <= chart.y_max + 1e-9 * step;
       v += step) {
    const std::string y = Fixed(y_of(v), 2);
    svg << "<line x1=\"" << left << "\" x2=\"" << left + plot_w << "\" y1=\"" << y << "\" y2=\""
        << y << "\" stroke=\"#dddddd\"/>\n"
        << "<text x=\"" << left - 6 << "\" y=\"" << y << "\" dy=\"4\" text-anchor=\"end\">"
        << Fixed(std::abs(v) < 1e-12 ? 0.0 : v, decimals) << "</text>\n";
  }
  svg << "<line x1=\"" << left << "\" x2=\"" << left << "\" y1=\"" << top << "\" y2=\""
      << top + plot_h << "\" stroke=\"black\"/>\n"
      << "<line x1=\"" << left << "\" x2=\"" << left + plot_w << "\" y1=\"" << top + plot_h
      << "\" y2=\"" << top + plot_h << "\" stroke=\"black\"/>\n"
      << "<text transform=\"translate(18," << Fixed(top + plot_h / 2, 1)
      << ") rotate(-90)\" text-anchor=\"middle\">" << EscapeXml(chart.y_label) << "</text>\n"
      << "<text x=\"" << Fixed(left + plot_w / 2, 1) << "\" y=\"" << chart.height - 8
      << "\" text-anchor=\"middle\">" << EscapeXml(chart.x_label) << "</text>\n";
  // Bars.
  double x = left + 0.25 * unit;
  const double base = y_of(std::clamp(0.0, chart.y_min, chart.y_max));
  for (const auto& bar : chart.bars) {
    x += bar.gap_before * unit;
    const double y = y_of(bar.value);
    const double y0 = std::min(y, base), h = std::abs(base - y);
    const char* colour = kColours[std::abs(bar.series) % 8];
    svg << "<rect x=\"" << Fixed(x, 2) << "\" y=\"" << Fixed(y0, 2) << "\" width=\""
        << Fixed(unit, 2) << "\" height=\"" << Fixed(h, 2) << "\" fill=\"" << colour << "\"><title>"
        << EscapeXml(bar.label) << ": " << FormatNumber(bar.value) << "</title></rect>\n";
    const double cx = x + unit / 2;
    if (bar.error) {
      const std::string y1 = Fixed(y_of(bar.value - *bar.error), 2);
      const std::string y2 = Fixed(y_of(bar.value + *bar.error), 2);
      const double w = std::min(6.0, unit / 3);
      svg << "<path d=\"M" << Fixed(cx, 2) << ' ' << y1 << "V" << y2 << "M" << Fixed(cx - w, 2)
          << ' ' << y1 << "H" << Fixed(cx + w, 2) << "M" << Fixed(cx - w, 2) << ' ' << y2 << "H"
          << Fixed(cx + w, 2) << "\" stroke=\"black\" fill=\"none\"/>\n";
    }
    if (!bar.label.empty()) {
      const double ly = top + plot_h + 14;
      if (rotate) {
        svg << "<text transform=\"translate(" << Fixed(cx + 3, 2) << ',' << Fixed(ly - 6, 2)
            << ") rotate(-60)\" text-anchor=\"end\" font-size=\"9\">" << EscapeXml(bar.label)
            << "</text>\n";
      } else {
        svg << "<text x=\"" << Fixed(cx, 2) << "\" y=\"" << Fixed(ly, 2)
            << "\" text-anchor=\"middle\">" << EscapeXml(bar.label) << "</text>\n";
      }
    }
    x += 1.25 * unit;
  }
  if (chart.reference) {
    const std::string y = Fixed(y_of(*chart.reference), 2);
    svg << "<line x1=\"" << left << "\" x2=\"" << left + plot_w << "\" y1=\"" << y << "\" y2=\""
        << y << "\" stroke=\"red\" stroke-width=\"1.5\"/>\n";
    if (!chart.reference_label.empty()) {
      svg << "<text x=\"" << left + plot_w - 4 << "\" y=\"" << y
          << "\" dy=\"-4\" text-anchor=\"end\" fill=\"red\">" << EscapeXml(chart.reference_label)
          << "</text>\n";
    }
  }
  if (chart.series_names.size() > 1) {
    double lx = left + 10;
    for (std::size_t s = 0; s < chart.series_names.size(); ++s) {
      svg << "<rect x=\"" << Fixed(lx, 1) << "\" y=\"" << top - 12
          << "\" width=\"10\" height=\"10\" fill=\"" << kColours[s % 8] << "\"/><text x=\""
          << Fixed(lx + 14, 1) << "\" y=\"" << top - 3 << "\">" << EscapeXml(chart.series_names[s])
          << "</text>\n";
      lx += 24 + 7.0 * chart.series_names[s].size();
    }
  }
  svg << "</svg>\n";
  return svg.str();
}

}  // namespace mmh::study
