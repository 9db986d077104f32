// Figures 8-11 of the paper's user study, as SVG with the CSV of their numbers:
//
//   figure8_mean_ranks      mean rank of each take (recording order) and the montage, by the
//                           animators, with standard errors (paper: Figure 8)
//   figure9_take_scores     m_ij, the share of scorers preferring the montage to take j, for every
//                           animator's takes (Figure 9)
//   figure10_all_takes      b_i = m_i1 m_i2 m_i3 per animator, the chance line at 0.125 (Figure 10)
//   figure11_take_order     mean m_ij per take with standard errors (Figure 11)
#pragma once

#include <string>
#include <vector>

#include "study/study_analysis.h"
#include "study/study_data.h"

namespace mmh::study {

struct Figure {
  std::string name;  // file stem, e.g. "figure8_mean_ranks"
  std::string svg;
  std::string csv;
};

std::vector<Figure> StudyFigures(const StudyData& data, const StudyAnalysis& analysis);

// Mean rank and its standard error per item: takes in recording order, then the montage.
struct ItemRank {
  std::string item;
  double mean_rank = 0.0;
  double standard_error = 0.0;
  int n = 0;
};
std::vector<ItemRank> MeanRanksByItem(const std::vector<RankingRow>& rankings);

}  // namespace mmh::study
