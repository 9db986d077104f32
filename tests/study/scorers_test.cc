// The simulated scoring phase: the paper's design (42 scorers, 420 comparisons, 7 per take, 10
// animators per scorer, nobody judging their own work) for the paper's size and others, and the
// viewers' preferences.
#include "study/scorers.h"

#include <gtest/gtest.h>

#include <map>
#include <set>

#include "core/error.h"
#include "study/study_data.h"

namespace mmh::study {
namespace {

void ExpectValidDesign(const ScoringDesign& design, const ScorerOptions& options) {
  const int c = options.comparisons_per_take;
  const int per_scorer = std::min(options.animators_per_scorer, design.animators - 1);
  EXPECT_EQ(static_cast<int>(design.comparisons.size()), design.animators * design.takes * c);
  std::map<std::pair<int, int>, int> per_take;
  std::map<int, std::multiset<int>> animators_of;
  for (const auto& a : design.comparisons) {
    ASSERT_GE(a.scorer, 0);
    ASSERT_LT(a.scorer, design.scorers);
    ASSERT_GE(a.take, 0);
    ASSERT_LT(a.take, design.takes);
    EXPECT_NE(a.scorer, a.animator) << "scorer " << a.scorer << " judges their own work";
    ++per_take[{a.animator, a.take}];
    animators_of[a.scorer].insert(a.animator);
  }
  EXPECT_EQ(static_cast<int>(per_take.size()), design.animators * design.takes);
  for (const auto& [cell, count] : per_take) EXPECT_EQ(count, c);
  for (const auto& [scorer, animators] : animators_of) {
    EXPECT_LE(static_cast<int>(animators.size()), per_scorer);
    EXPECT_EQ(std::set<int>(animators.begin(), animators.end()).size(), animators.size())
        << "scorer " << scorer << " sees an animator twice";
  }
}

TEST(ScorersTest, PaperDesign) {
  ScorerOptions options;
  EXPECT_EQ(ScorerCount(options, 20, 3), 42);
  for (const std::uint64_t seed : {1u, 2u, 3u, 99u}) {
    const ScoringDesign design = DrawScoringDesign(options, 20, 3, seed);
    EXPECT_EQ(design.scorers, 42);
    EXPECT_EQ(design.comparisons.size(), 420u);
    ExpectValidDesign(design, options);
    // Every scorer judges exactly 10 animators (42 x 10 = 420).
    std::map<int, int> count;
    for (const auto& a : design.comparisons) ++count[a.scorer];
    EXPECT_EQ(count.size(), 42u);
    for (const auto& [scorer, n] : count) EXPECT_EQ(n, 10);
  }
}

TEST(ScorersTest, OtherSizesFollowTheRule) {
  ScorerOptions options;
  // S = ceil(N K c / min(10, N - 1)).
  EXPECT_EQ(ScorerCount(options, 3, 3), 32);   // 63 / 2
  EXPECT_EQ(ScorerCount(options, 4, 3), 28);   // 84 / 3
  EXPECT_EQ(ScorerCount(options, 10, 3), 24);  // 210 / 9 = 23.3
  EXPECT_EQ(ScorerCount(options, 40, 3), 84);
  for (const int n : {3, 4, 5, 10, 13, 40}) {
    ExpectValidDesign(DrawScoringDesign(options, n, 3, 7), options);
  }
  ScorerOptions two_takes;
  two_takes.comparisons_per_take = 3;
  two_takes.animators_per_scorer = 4;
  ExpectValidDesign(DrawScoringDesign(two_takes, 6, 2, 5), two_takes);
}

TEST(ScorersTest, DeterministicInTheSeed) {
  const ScorerOptions options;
  const auto a = DrawScoringDesign(options, 20, 3, 4);
  const auto b = DrawScoringDesign(options, 20, 3, 4);
  const auto c = DrawScoringDesign(options, 20, 3, 5);
  ASSERT_EQ(a.comparisons.size(), b.comparisons.size());
  bool differs = false;
  for (std::size_t i = 0; i < a.comparisons.size(); ++i) {
    EXPECT_EQ(a.comparisons[i].scorer, b.comparisons[i].scorer);
    EXPECT_EQ(a.comparisons[i].animator, b.comparisons[i].animator);
    EXPECT_EQ(a.comparisons[i].take, b.comparisons[i].take);
    differs |= a.comparisons[i].animator != c.comparisons[i].animator ||
               a.comparisons[i].take != c.comparisons[i].take;
  }
  EXPECT_TRUE(differs);
}

TEST(ScorersTest, ImpossibleDesignsAreInputErrors) {
  ScorerOptions options;
  options.count = 30;  // 420 comparisons need 42 scorers at 10 each
  EXPECT_THROW(ScorerCount(options, 20, 3), InputError);
  options.count = 10;  // fewer scorers than animators
  EXPECT_THROW(ScorerCount(options, 20, 3), InputError);
  options = {};
  options.comparisons_per_take = 0;
  EXPECT_THROW(ScorerCount(options, 20, 3), InputError);
  EXPECT_THROW(ScorerCount(ScorerOptions{}, 1, 3), InputError);
}

people::Appeal AppealOf(double quality, double artefacts_per_minute = 0) {
  people::Appeal a;
  a.mean_quality = quality;
  a.artefacts_per_minute = artefacts_per_minute;
  a.appeal = quality - 0.025 * artefacts_per_minute;
  return a;
}

TEST(ScorersTest, ViewersPreferTheBetterAnimation) {
  const ScorerOptions options;
  const ScoringDesign design = DrawScoringDesign(options, 20, 3, 11);
  people::ViewerOptions viewer;
  viewer.judgement_noise = 0.05;  // the hand-set σ: differences of 0.3 always decide
  // Montage clearly better (0.3 quality above the takes; noise sd 0.05): it wins every time.
  std::vector<AnimationAppeals> better(20);
  for (auto& a : better) {
    a.takes = {AppealOf(0.4), AppealOf(0.45), AppealOf(0.5)};
    a.montage = AppealOf(0.8);
  }
  const auto rows = JudgeComparisons(design, better, viewer, 3);
  ASSERT_EQ(rows.size(), 420u);
  for (const auto& row : rows) EXPECT_TRUE(row.montage_preferred);
  // Equal appeal: the viewing noise decides, about half each (binomial sd sqrt(420)/2 = 10).
  std::vector<AnimationAppeals> equal(20);
  for (auto& a : equal) {
    a.takes = {AppealOf(0.5), AppealOf(0.5), AppealOf(0.5)};
    a.montage = AppealOf(0.5);
  }
  int wins = 0;
  for (const auto& row : JudgeComparisons(design, equal, viewer, 3)) wins += row.montage_preferred;
  EXPECT_NEAR(wins, 210, 45);
  // IDs: animators' scorer IDs are their animator IDs, the others S01..S22; no self-comparisons.
  std::set<std::string> scorers;
  for (const auto& row : rows) {
    scorers.insert(row.scorer);
    EXPECT_NE(row.scorer, row.animator);
  }
  EXPECT_EQ(scorers.size(), 42u);
  EXPECT_TRUE(scorers.count("A01") && scorers.count("A20") && scorers.count("S22"));
}

people::ViewerOptions PreciseViewer() {
  people::ViewerOptions viewer;
  viewer.judgement_noise = 0.05;
  return viewer;
}

people::SelfAppraisalOptions Unbiased() { return {.progress_weight = 0, .choice_bonus = 0}; }

TEST(ScorersTest, RankingsArePermutationsFollowingUtility) {
  std::vector<AnimationAppeals> appeals(5);
  for (auto& a : appeals) {
    a.takes = {AppealOf(0.2), AppealOf(0.5), AppealOf(0.8)};
    a.montage = AppealOf(0.95);
  }
  // Viewing noise far below the differences, no self-appraisal: the utilities decide.
  const auto rows = RankOwnAnimations(appeals, PreciseViewer(), Unbiased(), 1);
  ASSERT_EQ(rows.size(), 20u);
  StudyData data;
  data.rankings = rows;
  for (const auto& row : rows) {
    const double expected = row.item == "montage" ? 1
                            : row.item == "take3" ? 2
                            : row.item == "take2" ? 3
                                                  : 4;
    EXPECT_EQ(row.rank, expected) << row.animator << " " << row.item;
  }
}

// The self-appraisal biases reach the animators' rankings, not the scorers' comparisons.
TEST(ScorersTest, SelfAppraisalBiasesTheAnimatorsOnly) {
  std::vector<AnimationAppeals> appeals(20);
  for (auto& a : appeals) {
    // Take 1 best to any viewer, the montage worst (0.1 apart; viewing noise sd 0.05).
    a.takes = {AppealOf(0.8), AppealOf(0.7), AppealOf(0.6)};
    a.montage = AppealOf(0.5);
  }
  people::SelfAppraisalOptions biased;
  biased.progress_weight = 1.0;  // far larger than the differences: recording order decides
  biased.choice_bonus = 0.5;
  for (const auto& row : RankOwnAnimations(appeals, PreciseViewer(), biased, 1)) {
    const double expected = row.item == "montage" ? 1
                            : row.item == "take3" ? 2
                            : row.item == "take2" ? 3
                                                  : 4;
    EXPECT_EQ(row.rank, expected) << row.animator << " " << row.item;
  }
  // Without the biases take 1 ranks first for most animators.
  int take1_first = 0;
  for (const auto& row : RankOwnAnimations(appeals, PreciseViewer(), Unbiased(), 1)) {
    take1_first += row.item == "take1" && row.rank == 1;
  }
  EXPECT_GE(take1_first, 15);
}

}  // namespace
}  // namespace mmh::study
