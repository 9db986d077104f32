#include "study/study_analysis.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>

#include "core/annotation.h"
#include "core/error.h"
#include "core/options.h"
#include "stats/descriptive.h"

namespace mmh::study {
namespace {

// Runs `compute`; an InputError (the test is undefined on these data) becomes "not computed" with
// its message, and a warning naming `what`.
template <class R, class F>
Outcome<R> Attempt(const std::string& what, StudySummary* summary, F&& compute) {
  Outcome<R> outcome;
  try {
    outcome.result = compute();
  } catch (const InputError& e) {
    outcome.not_computed = e.what();
    summary->warnings.push_back(what + " not computed: " + e.what());
  }
  return outcome;
}

std::string Number(double value) { return std::isfinite(value) ? FormatNumber(value) : ""; }

// Short form for the report: 4 significant digits.
std::string Short(double value) {
  if (std::isinf(value)) return value > 0 ? "Inf" : "-Inf";
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.4g", value);
  return buffer;
}

std::string Interval(const stats::ConfidenceInterval& ci) {
  // An infinite end is open: [0.6, Inf).
  return Short(100.0 * ci.level) + "% CI " + (std::isinf(ci.lower) ? "(" : "[") + Short(ci.lower) +
         ", " + Short(ci.upper) + (std::isinf(ci.upper) ? ")" : "]");
}

// One row of tests.csv.
struct TestRow {
  std::string analysis, test, statistic_name;
  double statistic = NAN, df1 = NAN, df2 = NAN, p_value = NAN, estimate = NAN;
  double conf_low = NAN, conf_high = NAN, conf_level = NAN;
  std::string effect_size_name = "";
  double effect_size = NAN, n = NAN;
};

std::string TestRowCsv(const TestRow& r) {
  // One-sided interval ends are written as -Inf / Inf (R's and pandas' spelling).
  const auto end = [](double v) { return std::isinf(v) ? (v > 0 ? "Inf" : "-Inf") : Number(v); };
  return r.analysis + "," + r.test + "," + r.statistic_name + "," + Number(r.statistic) + "," +
         Number(r.df1) + "," + Number(r.df2) + "," + Number(r.p_value) + "," + Number(r.estimate) +
         "," + end(r.conf_low) + "," + end(r.conf_high) + "," + Number(r.conf_level) + "," +
         r.effect_size_name + "," + Number(r.effect_size) + "," + Number(r.n) + "\n";
}

// Sets the p-value, the estimate and its interval of `row`.
TestRow& SetEstimate(TestRow& row, double p_value, double estimate,
                     const stats::ConfidenceInterval& ci) {
  row.p_value = p_value;
  row.estimate = estimate;
  row.conf_low = ci.lower;
  row.conf_high = ci.upper;
  row.conf_level = ci.level;
  return row;
}

TestRow TRow(const std::string& analysis, const stats::TTestResult& t) {
  TestRow row{.analysis = analysis,
              .test = "one-sample t-test",
              .statistic_name = "t",
              .statistic = t.t,
              .df1 = t.df};
  SetEstimate(row, t.p_value, t.mean, t.conf_int);
  row.effect_size_name = "cohens_d";
  row.effect_size = t.cohens_d;
  row.n = static_cast<double>(t.n);
  return row;
}

TestRow FriedmanRow(const stats::FriedmanResult& f) {
  TestRow row{.analysis = "rankings",
              .test = "Friedman rank sum test",
              .statistic_name = "chi-squared",
              .statistic = f.statistic,
              .df1 = f.df};
  row.p_value = f.p_value;
  row.effect_size_name = "kendalls_w";
  row.effect_size = f.kendalls_w;
  row.n = static_cast<double>(f.blocks);
  return row;
}

TestRow BinomialRow(const std::string& analysis, const stats::BinomialTestResult& b) {
  TestRow row{.analysis = analysis,
              .test = "exact binomial test",
              .statistic_name = "successes",
              .statistic = static_cast<double>(b.successes)};
  SetEstimate(row, b.p_value, b.estimate, b.conf_int);
  row.effect_size_name = "cohens_h";
  row.effect_size = b.cohens_h;
  row.n = static_cast<double>(b.trials);
  return row;
}

TestRow ChiRow(const std::string& analysis, const stats::ChiSquaredResult& c) {
  TestRow row{.analysis = analysis,
              .test = c.method,
              .statistic_name = "X-squared",
              .statistic = c.statistic,
              .df1 = c.df};
  row.p_value = c.p_value;
  row.effect_size_name = c.effect_size_name;
  row.effect_size = c.effect_size;
  row.n = c.total;
  return row;
}

TestRow ShapiroRow(const std::string& analysis, const stats::ShapiroWilkResult& s) {
  TestRow row{.analysis = analysis,
              .test = "Shapiro-Wilk normality test",
              .statistic_name = "W",
              .statistic = s.w};
  row.p_value = s.p_value;
  row.n = static_cast<double>(s.n);
  return row;
}

TestRow FRow(const std::string& analysis, const std::string& test, const stats::FTest& f,
             double n) {
  TestRow row{.analysis = analysis,
              .test = test,
              .statistic_name = "F",
              .statistic = f.f,
              .df1 = f.num_df,
              .df2 = f.den_df};
  row.p_value = f.p_value;
  row.effect_size_name = "partial_eta_squared";
  row.effect_size = f.partial_eta_squared;
  row.n = n;
  return row;
}

}  // namespace

std::span<const std::pair<H1Unit, const char*>> EnumNames(H1Unit) {
  static constexpr std::array<std::pair<H1Unit, const char*>, 2> kNames{{
      {H1Unit::kAnimatorMeans, "animator_means"},
      {H1Unit::kTakeScores, "take_scores"},
  }};
  return kNames;
}

void StudyAnalysisOptions::Validate(const std::string& prefix) const {
  stats::RequireConfidenceLevel(conf_level, prefix + ".conf_level");
  if (!(chance > 0.0 && chance < 1.0)) {
    ThrowBadValue(prefix + ".chance", FormatNumber(chance), "a probability in (0, 1)");
  }
  if (!(all_takes_chance > 0.0 && all_takes_chance < 1.0)) {
    ThrowBadValue(prefix + ".all_takes_chance", FormatNumber(all_takes_chance),
                  "a probability in (0, 1)");
  }
  RequireNonNegative(cost_increase_threshold_percent, prefix + ".cost_increase_threshold_percent",
                     "%");
  data.Validate(prefix + ".data");
  mixed_model.Validate(prefix + ".mixed_model");
}

nlohmann::json StudySummary::ToJson() const {
  return {{"animators", animators}, {"ranking_animators", ranking_animators},
          {"scorers", scorers},     {"comparisons", comparisons},
          {"takes", takes},         {"self_comparisons", self_comparisons},
          {"warnings", warnings}};
}

namespace {
nlohmann::json OptionalJson(const std::optional<double>& value) {
  return value ? nlohmann::json(*value) : nlohmann::json(nullptr);
}
}  // namespace

nlohmann::json SegmentConstraintAnalysis::ToJson() const {
  nlohmann::json per = nlohmann::json::array();
  for (const auto& a : animators) {
    per.push_back({{"animator", a.animator},
                   {"increase", a.increase},
                   {"increase_percent", a.increase_percent},
                   {"paper_scale_percent", OptionalJson(a.paper_scale_percent)},
                   {"increase_per_frame", OptionalJson(a.increase_per_frame)},
                   {"short_segments_unconstrained", a.short_segments_unconstrained}});
  }
  return {{"animators", per},
          {"animators_with_short_segments", animators_with_short_segments},
          {"max_increase_percent", max_increase_percent},
          {"mean_increase_percent", mean_increase_percent},
          {"max_paper_scale_percent", OptionalJson(max_paper_scale_percent)},
          {"mean_paper_scale_percent", OptionalJson(mean_paper_scale_percent)},
          {"max_increase_per_frame", OptionalJson(max_increase_per_frame)},
          {"all_below_threshold", all_below_threshold},
          {"threshold_scale", threshold_scale}};
}

namespace {

// A one-sample t-test against `mu` with the analysis's alternative and confidence level.
stats::TTestOptions OneSampleTTestOptions(double mu, const StudyAnalysisOptions& options) {
  stats::TTestOptions t;
  t.mu = mu;
  t.alternative = options.alternative;
  t.conf_level = options.conf_level;
  return t;
}

// The animators' rankings of their takes and the montage: Friedman over animators (blocks) x
// items (groups).
void AnalyzeRankings(const StudyData& data, StudyAnalysis& a) {
  std::map<std::string, std::map<std::string, double>> ranks;  // animator -> item -> rank
  std::set<std::string> items;
  for (const auto& r : data.rankings) {
    ranks[r.animator][r.item] = r.rank;
    items.insert(r.item);
  }
  a.rankings.items.assign(items.begin(), items.end());
  a.summary.ranking_animators = ranks.size();
  Eigen::MatrixXd y(static_cast<Eigen::Index>(ranks.size()),
                    static_cast<Eigen::Index>(items.size()));
  Eigen::Index i = 0;
  for (const auto& [animator, by_item] : ranks) {
    Eigen::Index j = 0;
    for (const auto& item : a.rankings.items) y(i, j++) = by_item.at(item);
    ++i;
  }
  a.rankings.friedman = Attempt<stats::FriedmanResult>("Friedman test", &a.summary,
                                                       [&] { return stats::FriedmanTest(y); });
}

// m_ij: the share of comparisons in which animator i's montage was preferred over their take j
// (paper, "Results"), with the study's counts in the summary.
void ScoreTakes(const StudyData& data, StudyAnalysis& a) {
  StudySummary& summary = a.summary;
  std::map<std::pair<std::string, int>, TakeScore> cells;
  std::set<std::string> scorers;
  std::set<std::string> animators;
  for (const auto& c : data.comparisons) {
    TakeScore& cell = cells[{c.animator, c.take}];
    cell.animator = c.animator;
    cell.take = c.take;
    ++cell.comparisons;
    cell.montage_preferred += c.montage_preferred ? 1 : 0;
    scorers.insert(c.scorer);
    animators.insert(c.animator);
    summary.self_comparisons += c.scorer == c.animator ? 1 : 0;
    a.h1.wins += c.montage_preferred ? 1 : 0;
    summary.takes = std::max(summary.takes, c.take);
  }
  for (auto& [key, cell] : cells) {
    cell.m = static_cast<double>(cell.montage_preferred) / cell.comparisons;
    a.take_scores.push_back(cell);
  }
  summary.animators = animators.size();
  summary.scorers = scorers.size();
  summary.comparisons = data.comparisons.size();
  a.h1.comparisons = data.comparisons.size();
  if (summary.self_comparisons > 0) {
    summary.warnings.push_back(std::to_string(summary.self_comparisons) +
                               " comparisons by a scorer of their own animation (the paper "
                               "excluded these)");
  }
}

// H1: the montage is preferred over a take more often than by chance (t-test of the m_ij or of
// the animators' means, chi-squared and exact binomial test of the wins).
void AnalyzeH1(const StudyAnalysisOptions& options, StudyAnalysis& a) {
  std::vector<double> sample;
  if (options.h1_unit == H1Unit::kTakeScores) {
    for (const auto& s : a.take_scores) sample.push_back(s.m);
  } else {
    std::map<std::string, std::vector<double>> per_animator;
    for (const auto& s : a.take_scores) per_animator[s.animator].push_back(s.m);
    for (const auto& [animator, ms] : per_animator) sample.push_back(stats::Mean(ms));
  }
  a.h1.mean_m = stats::Mean(sample);
  a.h1.sd_m = sample.size() > 1 ? std::sqrt(stats::Variance(sample)) : NAN;
  const stats::TTestOptions t = OneSampleTTestOptions(options.chance, options);
  a.h1.t_test = Attempt<stats::TTestResult>("H1 t-test", &a.summary,
                                            [&] { return stats::OneSampleTTest(sample, t); });
  const std::vector<double> counts = {static_cast<double>(a.h1.wins),
                                      static_cast<double>(a.h1.comparisons - a.h1.wins)};
  const std::vector<double> p = {options.chance, 1.0 - options.chance};
  a.h1.chi_squared = Attempt<stats::ChiSquaredResult>(
      "H1 chi-squared test", &a.summary, [&] { return stats::ChiSquaredGoodnessOfFit(counts, p); });
  stats::BinomialTestOptions b;
  b.p = options.chance;
  b.alternative = options.alternative;
  b.conf_level = options.conf_level;
  a.h1.binomial = Attempt<stats::BinomialTestResult>("H1 binomial test", &a.summary, [&] {
    return stats::BinomialTest(static_cast<std::int64_t>(a.h1.wins),
                               static_cast<std::int64_t>(a.h1.comparisons), b);
  });
}

// H2: b_i = prod_j m_ij, over the animators with comparisons of every take, above the chance of
// preferring the montage over all takes.
void AnalyzeH2(const StudyAnalysisOptions& options, StudyAnalysis& a) {
  const int k = a.summary.takes;
  std::map<std::string, std::vector<const TakeScore*>> per_animator;
  for (const auto& s : a.take_scores) per_animator[s.animator].push_back(&s);
  std::vector<double> b;
  std::size_t incomplete = 0;
  for (const auto& [animator, scores] : per_animator) {
    if (static_cast<int>(scores.size()) != k) {
      ++incomplete;
      continue;
    }
    double product = 1.0;
    for (const auto* s : scores) product *= s->m;
    a.h2.b.emplace_back(animator, product);
    b.push_back(product);
  }
  if (incomplete > 0) {
    a.summary.warnings.push_back("H2 leaves out " + std::to_string(incomplete) +
                                 " animators without comparisons of all " + std::to_string(k) +
                                 " takes");
  }
  a.h2.normality = Attempt<stats::ShapiroWilkResult>("H2 Shapiro-Wilk test", &a.summary,
                                                     [&] { return stats::ShapiroWilkTest(b); });
  const stats::TTestOptions t = OneSampleTTestOptions(options.all_takes_chance, options);
  a.h2.t_test = Attempt<stats::TTestResult>("H2 t-test", &a.summary,
                                            [&] { return stats::OneSampleTTest(b, t); });
}

// H3: take order, m_ij ~ take + (1 | animator), its residuals' normality, and the take x
// preference table.
void AnalyzeH3(const StudyData& data, const StudyAnalysisOptions& options, StudyAnalysis& a) {
  const int k = a.summary.takes;
  std::map<std::string, int> animator_index;
  for (const auto& s : a.take_scores) animator_index.emplace(s.animator, 0);
  int next = 0;
  for (auto& [name, index] : animator_index) index = next++;
  std::vector<int> group;
  std::vector<int> level;
  std::vector<double> y;
  std::vector<std::vector<double>> by_take(static_cast<std::size_t>(k));
  for (const auto& s : a.take_scores) {
    group.push_back(animator_index.at(s.animator));
    level.push_back(s.take - 1);
    y.push_back(s.m);
    by_take[s.take - 1].push_back(s.m);
  }
  for (const auto& ms : by_take) {
    a.h3.take_means.push_back(stats::Mean(ms));
    a.h3.take_standard_errors.push_back(
        ms.size() > 1 ? std::sqrt(stats::Variance(ms) / static_cast<double>(ms.size())) : NAN);
  }
  a.h3.mixed_model = Attempt<stats::MixedModelResult>("H3 mixed model", &a.summary, [&] {
    return stats::FitRandomInterceptModel(group, level, y, options.mixed_model);
  });
  if (a.h3.mixed_model.result) {
    for (const auto& w : a.h3.mixed_model.result->summary.warnings) {
      a.summary.warnings.push_back("H3 mixed model: " + w);
    }
    a.h3.residual_normality = Attempt<stats::ShapiroWilkResult>(
        "H3 residual Shapiro-Wilk test", &a.summary,
        [&] { return stats::ShapiroWilkTest(a.h3.mixed_model.result->residuals); });
  } else {
    a.h3.residual_normality.not_computed = "no mixed model";
  }
  Eigen::MatrixXd table = Eigen::MatrixXd::Zero(k, 2);
  for (const auto& c : data.comparisons) table(c.take - 1, c.montage_preferred ? 0 : 1) += 1.0;
  a.h3.take_table = Attempt<stats::ChiSquaredResult>("H3 take x preference table", &a.summary, [&] {
    return stats::ChiSquaredIndependence(table, options.yates);
  });
}

// The Segment Length Constraint's cost (eqs. 7-12): the increase of the labelling's cost over
// the unconstrained optimum, relative to |unconstrained cost| and on the paper's scale (the
// annotation shifted to be non-negative, kMaxAnnotation per reference frame).
SegmentConstraintAnalysis AnalyzeSegmentConstraint(const StudyData& data,
                                                   const StudyAnalysisOptions& options) {
  SegmentConstraintAnalysis s;
  double sum = 0.0, paper_sum = 0.0;
  bool paper_scale = true;  // every animator with short segments has reference_frames
  bool relative_below = true, paper_below = true;
  double paper_max = 0.0, per_frame_max = 0.0;
  for (const auto& row : data.segment_costs) {
    SegmentConstraintAnalysis::Animator an;
    an.animator = row.animator;
    an.short_segments_unconstrained = row.short_segments_unconstrained;
    an.increase = row.cost_constrained - row.cost_unconstrained;
    an.increase_percent = row.cost_unconstrained == 0.0
                              ? 0.0
                              : 100.0 * an.increase / std::abs(row.cost_unconstrained);
    if (row.reference_frames > 0) {
      const double n = row.reference_frames;
      const double shifted = row.cost_unconstrained + kMaxAnnotation * n;
      if (shifted > 0) an.paper_scale_percent = 100.0 * an.increase / shifted;
      an.increase_per_frame = an.increase / n;
    }
    if (an.short_segments_unconstrained > 0) {
      ++s.animators_with_short_segments;
      s.max_increase_percent = std::max(s.max_increase_percent, an.increase_percent);
      sum += an.increase_percent;
      relative_below =
          relative_below && an.increase_percent < options.cost_increase_threshold_percent;
      if (an.paper_scale_percent) {
        paper_max = std::max(paper_max, *an.paper_scale_percent);
        per_frame_max = std::max(per_frame_max, *an.increase_per_frame);
        paper_sum += *an.paper_scale_percent;
        paper_below =
            paper_below && *an.paper_scale_percent < options.cost_increase_threshold_percent;
      } else {
        paper_scale = false;
      }
    }
    s.animators.push_back(an);
  }
  std::sort(s.animators.begin(), s.animators.end(),
            [](const auto& x, const auto& y) { return x.animator < y.animator; });
  const std::size_t k = s.animators_with_short_segments;
  s.mean_increase_percent = k ? sum / k : 0.0;
  if (paper_scale) {
    s.max_paper_scale_percent = paper_max;
    s.mean_paper_scale_percent = k ? paper_sum / k : 0.0;
    s.max_increase_per_frame = per_frame_max;
    s.all_below_threshold = paper_below;
    s.threshold_scale = "paper";
  } else {
    s.all_below_threshold = relative_below;
  }
  return s;
}

}  // namespace

StudyAnalysis AnalyzeStudy(const StudyData& data, const StudyAnalysisOptions& options) {
  options.Validate("stats");
  ValidateStudyData(data, options.data);
  StudyAnalysis a;
  a.options = options;
  AnalyzeRankings(data, a);
  ScoreTakes(data, a);
  AnalyzeH1(options, a);
  AnalyzeH2(options, a);
  AnalyzeH3(data, options, a);
  if (!data.segment_costs.empty()) a.segment_constraint = AnalyzeSegmentConstraint(data, options);
  return a;
}

nlohmann::json StudyAnalysis::ToJson() const {
  nlohmann::json j;
  j["options"] = mmh::ToJson(options);
  j["summary"] = summary.ToJson();
  nlohmann::json rank_json;
  rank_json["items"] = rankings.items;
  rank_json["friedman"] = rankings.friedman.ToJson();
  j["rankings"] = rank_json;
  j["h1"] = {{"unit", EnumName(options.h1_unit)},      {"mean_m", stats::FiniteOrNull(h1.mean_m)},
             {"sd_m", stats::FiniteOrNull(h1.sd_m)},   {"montage_preferred", h1.wins},
             {"comparisons", h1.comparisons},          {"t_test", h1.t_test.ToJson()},
             {"chi_squared", h1.chi_squared.ToJson()}, {"binomial", h1.binomial.ToJson()}};
  nlohmann::json b = nlohmann::json::array();
  for (const auto& [animator, value] : h2.b) b.push_back({{"animator", animator}, {"b", value}});
  j["h2"] = {{"b", b}, {"normality", h2.normality.ToJson()}, {"t_test", h2.t_test.ToJson()}};
  nlohmann::json se = nlohmann::json::array();
  for (double v : h3.take_standard_errors) se.push_back(stats::FiniteOrNull(v));
  j["h3"] = {{"take_means", h3.take_means},
             {"take_standard_errors", se},
             {"mixed_model", h3.mixed_model.ToJson()},
             {"residual_normality", h3.residual_normality.ToJson()},
             {"take_table", h3.take_table.ToJson()}};
  j["segment_constraint"] =
      segment_constraint ? segment_constraint->ToJson() : nlohmann::json(nullptr);
  return j;
}

std::string StudyAnalysis::TestsCsv() const {
  std::string out =
      "analysis,test,statistic_name,statistic,df1,df2,p_value,estimate,conf_low,conf_high,"
      "conf_level,effect_size_name,effect_size,n\n";
  if (rankings.friedman.result) out += TestRowCsv(FriedmanRow(*rankings.friedman.result));
  if (h1.t_test.result) out += TestRowCsv(TRow("h1", *h1.t_test.result));
  if (h1.chi_squared.result) out += TestRowCsv(ChiRow("h1", *h1.chi_squared.result));
  if (h1.binomial.result) out += TestRowCsv(BinomialRow("h1", *h1.binomial.result));
  if (h2.normality.result) out += TestRowCsv(ShapiroRow("h2", *h2.normality.result));
  if (h2.t_test.result) out += TestRowCsv(TRow("h2", *h2.t_test.result));
  if (const auto& m = h3.mixed_model.result) {
    const double n = static_cast<double>(m->summary.observations);
    out += TestRowCsv(FRow("h3", "mixed model F (Satterthwaite)", m->take_test, n));
    if (m->rm_anova) out += TestRowCsv(FRow("h3", "repeated-measures ANOVA F", *m->rm_anova, n));
    // The take differences (fixed effects after the intercept): take j minus take 1.
    for (std::size_t j = 1; j < m->fixed_effects.size(); ++j) {
      const stats::FixedEffect& e = m->fixed_effects[j];
      TestRow row{.analysis = "h3",
                  .test = "mixed model t (Satterthwaite) " + e.name + " - take1",
                  .statistic_name = "t",
                  .statistic = e.t,
                  .df1 = e.df};
      SetEstimate(row, e.p_value, e.estimate, e.conf_int).n = n;
      out += TestRowCsv(row);
    }
  }
  if (h3.residual_normality.result) {
    out += TestRowCsv(ShapiroRow("h3", *h3.residual_normality.result));
  }
  if (h3.take_table.result) out += TestRowCsv(ChiRow("h3", *h3.take_table.result));
  return out;
}

std::string StudyAnalysis::TakeScoresCsv() const {
  std::string out = "animator,take,comparisons,montage_preferred,m,fitted,residual\n";
  const stats::MixedModelResult* model = h3.mixed_model.result ? &*h3.mixed_model.result : nullptr;
  for (std::size_t i = 0; i < take_scores.size(); ++i) {
    const TakeScore& s = take_scores[i];
    out += s.animator + "," + std::to_string(s.take) + "," + std::to_string(s.comparisons) + "," +
           std::to_string(s.montage_preferred) + "," + Number(s.m) + "," +
           (model ? Number(model->fitted[i]) : "") + "," +
           (model ? Number(model->residuals[i]) : "") + "\n";
  }
  return out;
}

std::string StudyAnalysis::AnimatorScoresCsv() const {
  std::string out = "animator,b\n";
  for (const auto& [animator, b] : h2.b) out += animator + "," + Number(b) + "\n";
  return out;
}

std::string StudyAnalysis::MeanRanksCsv() const {
  std::string out = "item,rank_sum,mean_rank\n";
  if (const auto& f = rankings.friedman.result) {
    for (std::size_t j = 0; j < rankings.items.size(); ++j) {
      out +=
          rankings.items[j] + "," + Number(f->rank_sums[j]) + "," + Number(f->mean_ranks[j]) + "\n";
    }
  }
  return out;
}

std::string StudyAnalysis::Report() const {
  std::ostringstream out;
  const auto p = [](double v) { return "p = " + Short(v); };
  const std::string tail =
      options.alternative == stats::Alternative::kTwoSided ? "two-tailed" : "one-tailed";
  out << "data: " << summary.animators << " animators, " << summary.scorers << " scorers, "
      << summary.comparisons << " comparisons of " << summary.takes << " takes; "
      << summary.ranking_animators << " animators ranked " << rankings.items.size() << " items\n";
  if (const auto& f = rankings.friedman.result) {
    out << "rankings: Friedman chi2(df = " << Short(f->df) << ", N = " << f->blocks
        << ") = " << Short(f->statistic) << ", " << p(f->p_value)
        << ", Kendall's W = " << Short(f->kendalls_w) << "; mean ranks:";
    for (std::size_t j = 0; j < rankings.items.size(); ++j) {
      out << " " << rankings.items[j] << " " << Short(f->mean_ranks[j]);
    }
    out << "\n";
  } else {
    out << "rankings: Friedman test not computed (" << rankings.friedman.not_computed << ")\n";
  }
  out << "H1: mean m = " << Short(h1.mean_m) << " (SD " << Short(h1.sd_m) << ", "
      << EnumName(options.h1_unit) << ")";
  if (const auto& t = h1.t_test.result) {
    out << "; " << tail << " t(" << Short(t->df) << ") = " << Short(t->t) << ", " << p(t->p_value)
        << ", " << Interval(t->conf_int) << ", d = " << Short(t->cohens_d);
  }
  out << "\n    " << h1.wins << " of " << h1.comparisons << " comparisons won by the montage";
  if (const auto& c = h1.chi_squared.result) {
    out << "; chi2(" << Short(c->df) << ") = " << Short(c->statistic) << ", " << p(c->p_value);
  }
  if (const auto& b = h1.binomial.result) {
    out << "; exact binomial " << p(b->p_value) << ", " << Interval(b->conf_int);
  }
  out << "\n";
  if (const auto& t = h2.t_test.result) {
    out << "H2: mean b = " << Short(t->mean) << " (SD " << Short(t->sd) << ", n = " << t->n << ")";
    if (const auto& s = h2.normality.result) {
      out << "; Shapiro-Wilk W = " << Short(s->w) << ", " << p(s->p_value);
    }
    out << "; " << tail << " t(" << Short(t->df) << ") = " << Short(t->t) << ", " << p(t->p_value)
        << ", " << Interval(t->conf_int) << "\n";
  } else {
    out << "H2: t-test not computed (" << h2.t_test.not_computed << ")\n";
  }
  if (const auto& m = h3.mixed_model.result) {
    const stats::FTest& f = m->take_test;
    out << "H3: mixed model F(" << Short(f.num_df) << ", " << Short(f.den_df)
        << ") = " << Short(f.f) << ", " << p(f.p_value) << " (animator variance "
        << Short(m->group_variance) << ", residual " << Short(m->residual_variance)
        << (m->boundary ? ", at the boundary" : "") << ")";
    if (m->rm_anova) {
      out << "; repeated-measures ANOVA F(" << Short(m->rm_anova->num_df) << ", "
          << Short(m->rm_anova->den_df) << ") = " << Short(m->rm_anova->f) << ", "
          << p(m->rm_anova->p_value) << (m->agrees_with_rm_anova ? " (equal)" : " (differs)");
    }
    if (const auto& s = h3.residual_normality.result) {
      out << "; residuals Shapiro-Wilk W = " << Short(s->w) << ", " << p(s->p_value);
    }
    out << "\n";
  } else {
    out << "H3: mixed model not computed (" << h3.mixed_model.not_computed << ")\n";
  }
  if (const auto& c = h3.take_table.result) {
    out << "    take x preference: chi2(" << Short(c->df) << ") = " << Short(c->statistic) << ", "
        << p(c->p_value) << "\n";
  }
  if (segment_constraint) {
    const auto& s = *segment_constraint;
    out << "segments: " << s.animators_with_short_segments << " of " << s.animators.size()
        << " montages had short segments without the constraint; cost increase max "
        << Short(s.max_increase_percent) << " %, mean " << Short(s.mean_increase_percent)
        << " % of |C0|";
    if (s.max_paper_scale_percent) {
      out << "; on the paper's scale (C_d = 5 - a') max " << Short(*s.max_paper_scale_percent)
          << " %, mean " << Short(*s.mean_paper_scale_percent) << " %, at most "
          << Short(*s.max_increase_per_frame) << " slider units per frame";
    }
    out << " (" << (s.all_below_threshold ? "all" : "not all") << " below "
        << Short(options.cost_increase_threshold_percent) << " %"
        << (s.threshold_scale == "paper" ? " on the paper's scale" : " of |C0|") << ")\n";
  }
  for (const auto& w : summary.warnings) out << "warning: " << w << "\n";
  return out.str();
}

}  // namespace mmh::study
