// The statistics of the paper's user study ("User study: single object montage", Results),
// computed from StudyData (study_data.h) — what `mmh stats` prints and writes, and what the
// simulated study calls in memory:
//
//   rankings  Friedman test of the animators' ranks of their takes and montage (chi2(3), N = 20).
//   H1        m_ij = share of scorers preferring animator i's montage to take j; mean of m_ij
//             against `chance` with a one-tailed t-test (t(19): over the animators' mean m_i., see
//             H1Unit), and over all binary comparisons a chi-squared goodness of fit and an exact
//             binomial test.
//   H2        b_i = m_i1 m_i2 ... m_iK; Shapiro-Wilk normality, one-tailed t-test against
//             `all_takes_chance` (0.5^3 = 0.125).
//   H3        m_ij against take order: mixed model (take fixed, animator random intercept; lmer +
//             lmerTest), the repeated-measures ANOVA beside it when balanced, Shapiro-Wilk of the
//             model's residuals, and the take x preference contingency table.
//   segments  the Segment Length Constraint's cost increase (optional segment_costs.csv).
//
// A test that is undefined on the data (constant values, too few animators) is reported as not
// computed with the reason, and the Summary carries a warning; the rest is still computed.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "stats/binomial_test.h"
#include "stats/chi_squared_test.h"
#include "stats/friedman_test.h"
#include "stats/mixed_model.h"
#include "stats/shapiro_wilk.h"
#include "stats/t_test.h"
#include "study/study_data.h"

namespace mmh::study {

// The sample of H1's t-test. The paper reports t(19) for 20 animators, so its unit is the
// animator: the mean of m_ij over the animator's takes.
enum class H1Unit { kAnimatorMeans, kTakeScores };
std::span<const std::pair<H1Unit, const char*>> EnumNames(H1Unit);

struct StudyAnalysisOptions {
  // Coverage of every confidence interval.
  double conf_level = 0.95;
  // Alternative of H1's and H2's tests (paper: one-tailed, montage better than chance).
  stats::Alternative alternative = stats::Alternative::kGreater;
  // Probability that the montage wins a comparison by chance (paper: 0.5).
  double chance = 0.5;
  // Probability that the montage beats all takes by chance, H2's null mean of b_i (paper: 0.125 =
  // 0.5^3 for three takes).
  double all_takes_chance = 0.125;
  // Sample of H1's t-test (see H1Unit); "animator_means" reproduces the paper's df.
  H1Unit h1_unit = H1Unit::kAnimatorMeans;
  // Yates' correction for the take x preference table when it is 2x2 (two takes; R's default).
  bool yates = true;
  // Largest relative cost increase of the Segment Length Constraint called "small" [%] (paper:
  // "less than 1% in all the 10 cases").
  double cost_increase_threshold_percent = 1.0;
  StudyDataOptions data;
  stats::MixedModelOptions mixed_model;

  template <class V>
  void VisitFields(V& v) {
    v("conf_level", conf_level);
    v("alternative", alternative);
    v("chance", chance);
    v("all_takes_chance", all_takes_chance);
    v("h1_unit", h1_unit);
    v("yates", yates);
    v("cost_increase_threshold_percent", cost_increase_threshold_percent);
    v("data", data);
    v("mixed_model", mixed_model);
  }
  void Validate(const std::string& prefix) const;
};

// A test result, or the reason it could not be computed on these data.
template <class R>
struct Outcome {
  std::optional<R> result;
  std::string not_computed;  // reason, when !result

  nlohmann::json ToJson() const {
    return result ? result->ToJson() : nlohmann::json{{"not_computed", not_computed}};
  }
};

// m_ij: one animator's take, scored by the scorers who compared it with the montage.
struct TakeScore {
  std::string animator;
  int take = 0;
  int comparisons = 0;
  int montage_preferred = 0;
  double m = 0.0;  // montage_preferred / comparisons
};

struct StudySummary {
  std::size_t animators = 0;          // animators with comparisons
  std::size_t ranking_animators = 0;  // animators with rankings
  std::size_t scorers = 0;
  std::size_t comparisons = 0;
  int takes = 0;                     // K
  std::size_t self_comparisons = 0;  // scorer == animator (the paper avoided these)
  std::vector<std::string> warnings;

  nlohmann::json ToJson() const;
};

struct RankingAnalysis {
  std::vector<std::string> items;  // column order of the Friedman test (sorted names)
  Outcome<stats::FriedmanResult> friedman;
};

struct H1Analysis {
  double mean_m = 0.0;   // mean of the t-test's sample
  double sd_m = 0.0;     // its standard deviation
  std::size_t wins = 0;  // comparisons the montage won
  std::size_t comparisons = 0;
  Outcome<stats::TTestResult> t_test;
  Outcome<stats::ChiSquaredResult> chi_squared;
  Outcome<stats::BinomialTestResult> binomial;
};

struct H2Analysis {
  std::vector<std::pair<std::string, double>> b;  // (animator, b_i), animators with every take
  Outcome<stats::ShapiroWilkResult> normality;
  Outcome<stats::TTestResult> t_test;
};

struct H3Analysis {
  Outcome<stats::MixedModelResult> mixed_model;
  Outcome<stats::ShapiroWilkResult> residual_normality;
  Outcome<stats::ChiSquaredResult>
      take_table;                  // K x 2: per take, montage preferred / take preferred
  std::vector<double> take_means;  // mean m_ij per take (Figure 11)
  std::vector<double> take_standard_errors;
};

// The constraint's cost increase C − C0 (eq. 7 with d = 60 against d = 0) on three scales. The
// compositor's data cost C_d = −a'(t) (eq. 8) is negative where a take is liked, so C0 can be near
// 0 and 100 (C − C0) / |C0| is ill-conditioned. A percentage needs a cost whose zero means "no
// cost": shifting C_d by the slider's maximum, 5 − a'(t) ≥ 0 for an unwarped annotation, changes
// no optimum (a constant n·5 over the n reference frames) and makes C_T the distance from an
// all-liked montage plus the transitions' cost. "< 1 %" is read on that scale (the paper's scale):
//   paper_scale_percent = 100 (C − C0) / (C0 + 5 n),
// beside the absolute increase per reference frame, (C − C0) / n, in slider units.
struct SegmentConstraintAnalysis {
  struct Animator {
    std::string animator;
    double increase = 0.0;          // C − C0
    double increase_percent = 0.0;  // 100 (C − C0) / |C0| (0 when C0 = 0)
    std::optional<double> paper_scale_percent;  // needs reference_frames
    std::optional<double> increase_per_frame;   // (C − C0) / n, slider units
    int short_segments_unconstrained = 0;
  };
  std::vector<Animator> animators;
  std::size_t animators_with_short_segments = 0;  // "quick transitions" without the constraint
  double max_increase_percent = 0.0;              // among those
  double mean_increase_percent = 0.0;             // among those (0 if none)
  // Among those, when every one has reference_frames.
  std::optional<double> max_paper_scale_percent;
  std::optional<double> mean_paper_scale_percent;
  std::optional<double> max_increase_per_frame;
  // Every increase among those below options.cost_increase_threshold_percent: on the paper's
  // scale when known, else relative to |C0| (`threshold_scale` says which).
  bool all_below_threshold = true;
  std::string threshold_scale = "relative_to_abs_c0";

  nlohmann::json ToJson() const;
};

struct StudyAnalysis {
  StudyAnalysisOptions options;
  std::vector<TakeScore> take_scores;  // sorted by animator, take
  RankingAnalysis rankings;
  H1Analysis h1;
  H2Analysis h2;
  H3Analysis h3;
  std::optional<SegmentConstraintAnalysis> segment_constraint;
  StudySummary summary;

  nlohmann::json ToJson() const;
  // Tidy CSVs: one row per test (analysis, test, statistic, df, p, estimate, CI, effect size);
  // per (animator, take) scores with the mixed model's fitted values and residuals; per animator
  // b_i; mean ranks per item.
  std::string TestsCsv() const;
  std::string TakeScoresCsv() const;
  std::string AnimatorScoresCsv() const;
  std::string MeanRanksCsv() const;
  // Human-readable report, the paper's way of writing each result.
  std::string Report() const;
};

// Validates the data (ValidateStudyData) and computes every analysis.
StudyAnalysis AnalyzeStudy(const StudyData& data, const StudyAnalysisOptions& options = {});

}  // namespace mmh::study
