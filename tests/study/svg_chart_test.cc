// The SVG bar chart writer: round tick steps, escaping, bar geometry against the axis scale.
#include "study/svg_chart.h"

#include <gtest/gtest.h>

#include <regex>

#include "core/error.h"

namespace mmh::study {
namespace {

TEST(SvgChartTest, TickSteps) {
  EXPECT_DOUBLE_EQ(TickStep(1.0), 0.2);
  EXPECT_DOUBLE_EQ(TickStep(4.0), 1.0);
  EXPECT_DOUBLE_EQ(TickStep(0.5), 0.1);
  EXPECT_DOUBLE_EQ(TickStep(100.0), 20.0);
  EXPECT_DOUBLE_EQ(TickStep(7.0), 2.0);
  EXPECT_DOUBLE_EQ(TickStep(0.0), 1.0);
}

TEST(SvgChartTest, EscapesText) {
  EXPECT_EQ(EscapeXml("a < b & \"c\" > d"), "a &lt; b &amp; &quot;c&quot; &gt; d");
}

TEST(SvgChartTest, BarHeightsFollowTheScale) {
  BarChart chart;
  chart.title = "T <1>";
  chart.y_min = 0;
  chart.y_max = 1;
  chart.height = 400;  // plot from y = 40 to 340 (300 px for 1.0)
  chart.bars = {{"a", 0.5, 0.1, 0, 0.0}, {"b", 1.5, std::nullopt, 1, 0.0}};
  chart.reference = 0.25;
  const std::string svg = BarChartSvg(chart);
  EXPECT_NE(svg.find("T &lt;1&gt;"), std::string::npos);
  // Bar a: 0.5 -> height 150 from y = 190; bar b clipped at 1.0 -> height 300 from y = 40.
  EXPECT_NE(svg.find("y=\"190.00\" width="), std::string::npos) << svg;
  EXPECT_NE(svg.find("height=\"150.00\""), std::string::npos);
  EXPECT_NE(svg.find("y=\"40.00\" width="), std::string::npos);
  EXPECT_NE(svg.find("height=\"300.00\""), std::string::npos);
  // Error bar of bar a from 0.4 (y 220) to 0.6 (y 160); reference line at 0.25 (y 265).
  EXPECT_NE(svg.find("220.00V160.00"), std::string::npos);
  EXPECT_NE(svg.find("y1=\"265.00\" y2=\"265.00\" stroke=\"red\""), std::string::npos);
  // Balanced tags: as many rect openings as closings or self-closings.
  const std::regex rect("<rect");
  EXPECT_EQ(
      std::distance(std::sregex_iterator(svg.begin(), svg.end(), rect), std::sregex_iterator()),
      3);  // background and two bars
  EXPECT_EQ(svg.substr(svg.size() - 7), "</svg>\n");
}

TEST(SvgChartTest, BadRangeIsAnInputError) {
  BarChart chart;
  chart.y_min = 1;
  chart.y_max = 1;
  EXPECT_THROW(BarChartSvg(chart), InputError);
}

}  // namespace
}  // namespace mmh::study
