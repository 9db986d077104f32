#include "study/figures.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "core/error.h"
#include "study/svg_chart.h"

namespace mmh::study {
namespace {

std::string Num(double value) { return FormatNumber(value); }

// Takes by number, then anything else (the montage) by name.
bool ItemBefore(const std::string& a, const std::string& b) {
  const int ka = TakeNumberOfItem(a), kb = TakeNumberOfItem(b);
  if ((ka > 0) != (kb > 0)) return ka > 0;
  return ka > 0 ? ka < kb : a < b;
}

Figure MeanRanksFigure(const StudyData& data) {
  const auto ranks = MeanRanksByItem(data.rankings);
  BarChart chart;
  chart.title = "Figure 8. Average ranks by the animators (1 = best)";
  chart.x_label = "animation";
  chart.y_label = "average rank";
  chart.y_min = 0;
  chart.y_max = std::max<double>(1, static_cast<double>(ranks.size()));
  std::ostringstream csv;
  csv << "item,mean_rank,standard_error,n\n";
  for (const auto& r : ranks) {
    chart.bars.push_back(
        {r.item, r.mean_rank, r.standard_error, r.item == kMontageItem ? 1 : 0, 0.0});
    csv << r.item << ',' << Num(r.mean_rank) << ',' << Num(r.standard_error) << ',' << r.n << '\n';
  }
  return {"figure8_mean_ranks", BarChartSvg(chart), csv.str()};
}

Figure TakeScoresFigure(const StudyAnalysis& analysis) {
  BarChart chart;
  chart.title = "Figure 9. Probability that the montage is better than a take";
  chart.x_label = "animator, take";
  chart.y_label = "m_ij (share of scorers preferring the montage)";
  chart.reference = 0.5;
  chart.reference_label = "chance 0.5";
  std::ostringstream csv;
  csv << "animator,take,comparisons,montage_preferred,m\n";
  int takes = 0;
  std::string previous;
  for (const auto& s : analysis.take_scores) {
    takes = std::max(takes, s.take);
    const bool first = s.animator != previous;
    chart.bars.push_back({first ? s.animator : "", s.m, std::nullopt, s.take - 1,
                          first && !previous.empty() ? 0.6 : 0.0});
    previous = s.animator;
    csv << s.animator << ',' << s.take << ',' << s.comparisons << ',' << s.montage_preferred << ','
        << Num(s.m) << '\n';
  }
  for (int k = 1; k <= takes; ++k) chart.series_names.push_back("take " + std::to_string(k));
  return {"figure9_take_scores", BarChartSvg(chart), csv.str()};
}

Figure AllTakesFigure(const StudyAnalysis& analysis) {
  BarChart chart;
  chart.title = "Figure 10. Probability that the montage is better than all the takes";
  chart.x_label = "animator";
  chart.y_label = "b_i = m_i1 m_i2 m_i3";
  chart.reference = analysis.options.all_takes_chance;
  chart.reference_label = "chance " + Num(analysis.options.all_takes_chance);
  double top = 0.5;
  std::ostringstream csv;
  csv << "animator,b\n";
  for (const auto& [animator, b] : analysis.h2.b) {
    chart.bars.push_back({animator, b, std::nullopt, 0, 0.0});
    top = std::max(top, b);
    csv << animator << ',' << Num(b) << '\n';
  }
  chart.y_max = std::min(1.0, std::ceil(top * 10) / 10);
  return {"figure10_all_takes", BarChartSvg(chart), csv.str()};
}

Figure TakeOrderFigure(const StudyAnalysis& analysis) {
  BarChart chart;
  chart.title = "Figure 11. Probability that the montage is better than a take, by take order";
  chart.x_label = "take (recording order)";
  chart.y_label = "mean m_ij (± standard error)";
  chart.reference = analysis.options.chance;
  chart.reference_label = "chance " + Num(analysis.options.chance);
  std::ostringstream csv;
  csv << "take,mean_m,standard_error\n";
  for (std::size_t k = 0; k < analysis.h3.take_means.size(); ++k) {
    const double se =
        k < analysis.h3.take_standard_errors.size() ? analysis.h3.take_standard_errors[k] : 0.0;
    chart.bars.push_back({"take " + std::to_string(k + 1), analysis.h3.take_means[k],
                          std::isfinite(se) ? std::optional<double>(se) : std::nullopt, 0, 0.0});
    csv << k + 1 << ',' << Num(analysis.h3.take_means[k]) << ',' << Num(se) << '\n';
  }
  return {"figure11_take_order", BarChartSvg(chart), csv.str()};
}

}  // namespace

std::vector<ItemRank> MeanRanksByItem(const std::vector<RankingRow>& rankings) {
  std::map<std::string, std::vector<double>> by_item;
  for (const auto& row : rankings) by_item[row.item].push_back(row.rank);
  std::vector<ItemRank> out;
  for (const auto& [item, ranks] : by_item) {
    ItemRank r;
    r.item = item;
    r.n = static_cast<int>(ranks.size());
    double sum = 0;
    for (const double v : ranks) sum += v;
    r.mean_rank = sum / r.n;
    if (r.n > 1) {
      double ss = 0;
      for (const double v : ranks) ss += (v - r.mean_rank) * (v - r.mean_rank);
      r.standard_error = std::sqrt(ss / (r.n - 1) / r.n);
    }
    out.push_back(r);
  }
  std::sort(out.begin(), out.end(),
            [](const ItemRank& a, const ItemRank& b) { return ItemBefore(a.item, b.item); });
  return out;
}

std::vector<Figure> StudyFigures(const StudyData& data, const StudyAnalysis& analysis) {
  return {MeanRanksFigure(data), TakeScoresFigure(analysis), AllTakesFigure(analysis),
          TakeOrderFigure(analysis)};
}

}  // namespace mmh::study
