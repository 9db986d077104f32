#include "study/study_analysis.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <random>

#include "tests/stats/golden.h"
#include "tests/test_util.h"

namespace mmh::study {
namespace {

using stats::golden::Near;
using test_util::TempDir;

const std::filesystem::path kExample =
    std::filesystem::path(MMH_SOURCE_DIR) / "examples" / "study_data";
const std::filesystem::path kAnalyzeScript =
    std::filesystem::path(MMH_TEST_DATA_DIR) / "study" / "analyze_study.R";

void ExpectHtest(const stats::TTestResult& t, const nlohmann::json& r) {
  MMH_EXPECT_NEAR_R(t.t, r.at("statistic").get<double>());
  MMH_EXPECT_NEAR_R(t.df, r.at("parameter").get<double>());
  MMH_EXPECT_NEAR_R(t.p_value, r.at("p_value").get<double>());
  MMH_EXPECT_NEAR_R(t.conf_int.lower, stats::golden::Number(r.at("conf_int")[0], -1.0));
  MMH_EXPECT_NEAR_R(t.conf_int.upper, stats::golden::Number(r.at("conf_int")[1], 1.0));
}

// Every number of AnalyzeStudy against R's analysis of the same CSV files (analyze_study.R).
void ExpectMatchesR(const StudyAnalysis& a, const nlohmann::json& r) {
  ASSERT_TRUE(a.rankings.friedman.result);
  MMH_EXPECT_NEAR_R(a.rankings.friedman.result->statistic,
                    r.at("friedman").at("statistic").get<double>());
  MMH_EXPECT_NEAR_R(a.rankings.friedman.result->p_value,
                    r.at("friedman").at("p_value").get<double>());

  const auto& h1 = r.at("h1");
  MMH_EXPECT_NEAR_R(a.h1.mean_m, h1.at("mean_m").get<double>());
  MMH_EXPECT_NEAR_R(a.h1.sd_m, h1.at("sd_m").get<double>());
  EXPECT_EQ(a.h1.wins, h1.at("wins").get<std::size_t>());
  ASSERT_TRUE(a.h1.t_test.result && a.h1.chi_squared.result && a.h1.binomial.result);
  ExpectHtest(*a.h1.t_test.result, h1.at("t_test"));
  MMH_EXPECT_NEAR_R(a.h1.chi_squared.result->statistic,
                    h1.at("chi_squared").at("statistic").get<double>());
  MMH_EXPECT_NEAR_R(a.h1.chi_squared.result->p_value,
                    h1.at("chi_squared").at("p_value").get<double>());
  MMH_EXPECT_NEAR_R(a.h1.binomial.result->p_value, h1.at("binomial").at("p_value").get<double>());
  MMH_EXPECT_NEAR_R(a.h1.binomial.result->conf_int.lower,
                    h1.at("binomial").at("conf_int")[0].get<double>());

  const auto& h2 = r.at("h2");
  const std::vector<double> b = stats::golden::Vector(h2.at("b"));
  ASSERT_EQ(a.h2.b.size(), b.size());
  for (std::size_t i = 0; i < b.size(); ++i) MMH_EXPECT_NEAR_R(a.h2.b[i].second, b[i]);
  ASSERT_TRUE(a.h2.normality.result && a.h2.t_test.result);
  MMH_EXPECT_NEAR_R(a.h2.normality.result->w, h2.at("shapiro").at("statistic").get<double>());
  MMH_EXPECT_NEAR_R(a.h2.normality.result->p_value, h2.at("shapiro").at("p_value").get<double>());
  ExpectHtest(*a.h2.t_test.result, h2.at("t_test"));

  const auto& h3 = r.at("h3");
  ASSERT_TRUE(a.h3.mixed_model.result);
  const stats::MixedModelResult& m = *a.h3.mixed_model.result;
  EXPECT_EQ(m.boundary, h3.at("singular").get<bool>());
  MMH_EXPECT_NEAR_R(m.sigma, h3.at("sigma").get<double>());
  MMH_EXPECT_NEAR_R(m.take_test.f, h3.at("anova").at("f").get<double>());
  MMH_EXPECT_NEAR_R(m.take_test.den_df, h3.at("anova").at("den_df").get<double>());
  MMH_EXPECT_NEAR_R(m.take_test.p_value, h3.at("anova").at("p_value").get<double>());
  ASSERT_EQ(m.rm_anova.has_value(), !h3.at("rm_anova").is_null());
  if (m.rm_anova) {
    MMH_EXPECT_NEAR_R(m.rm_anova->f, h3.at("rm_anova").at("f").get<double>());
    MMH_EXPECT_NEAR_R(m.rm_anova->p_value, h3.at("rm_anova").at("p_value").get<double>());
  }
  ASSERT_TRUE(a.h3.residual_normality.result && a.h3.take_table.result);
  MMH_EXPECT_NEAR_R(a.h3.residual_normality.result->w,
                    h3.at("residual_shapiro").at("statistic").get<double>());
  MMH_EXPECT_NEAR_R(a.h3.residual_normality.result->p_value,
                    h3.at("residual_shapiro").at("p_value").get<double>());
  MMH_EXPECT_NEAR_R(a.h3.take_table.result->statistic,
                    h3.at("take_table").at("statistic").get<double>());
  MMH_EXPECT_NEAR_R(a.h3.take_table.result->p_value,
                    h3.at("take_table").at("p_value").get<double>());
}

TEST(AnalyzeStudy, ExampleMatchesRsAnalysisOfTheSameCsvFiles) {
  const StudyAnalysis a = AnalyzeStudy(ReadStudyData(kExample));
  ExpectMatchesR(a, stats::golden::ReadJsonFile(std::filesystem::path(MMH_TEST_DATA_DIR) / "study" /
                                                "example_expected.json"));
  ASSERT_TRUE(a.segment_constraint);
  EXPECT_EQ(a.segment_constraint->animators_with_short_segments, 10u);
  EXPECT_TRUE(a.segment_constraint->all_below_threshold);
  EXPECT_TRUE(a.summary.warnings.empty()) << a.summary.warnings.front();
}

// A random study: unbalanced (some takes of some animators never compared), scorers that compare
// their own work, written as CSV and analysed both here and by R (when Rscript is installed).
StudyData RandomStudy(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  StudyData data;
  const int animators = 12;
  for (int a = 0; a < animators; ++a) {
    const std::string id = "A" + std::to_string(10 + a);
    std::vector<std::string> items = {"montage", "take1", "take2", "take3"};
    std::shuffle(items.begin() + (a % 3 == 0 ? 0 : 1), items.end(), rng);
    for (int i = 0; i < 4; ++i) data.rankings.push_back({id, items[i], i + 1.0});
    const double quality = uniform(rng);
    for (int take = 1; take <= 3; ++take) {
      if ((a + take) % 7 == 0) continue;  // never compared: unbalanced
      const int scorers = 3 + static_cast<int>(rng() % 5);
      for (int s = 0; s < scorers; ++s) {
        const bool won = uniform(rng) < 0.35 + 0.4 * quality + 0.05 * take;
        data.comparisons.push_back({"S" + std::to_string(s), id, take, won});
      }
    }
  }
  return data;
}

TEST(AnalyzeStudy, LiveRCheckOnRandomUnbalancedStudies) {
  if (std::system("command -v Rscript >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "Rscript not installed";
  }
  for (std::uint32_t seed : {1u, 2u}) {
    SCOPED_TRACE(seed);
    const StudyData data = RandomStudy(seed);
    TempDir dir;
    WriteStudyData(dir.path(), data);
    const std::string command = "Rscript '" + kAnalyzeScript.string() + "' '" +
                                dir.path().string() + "' '" + (dir / "r.json").string() + "' >'" +
                                (dir / "r.log").string() + "' 2>&1";
    ASSERT_EQ(std::system(command.c_str()), 0) << test_util::ReadBytes(dir / "r.log");
    const StudyAnalysis a = AnalyzeStudy(ReadStudyData(dir.path()));
    EXPECT_FALSE(a.h3.mixed_model.result->summary.balanced);
    ExpectMatchesR(a, stats::golden::ReadJsonFile(dir / "r.json"));
  }
}

TEST(AnalyzeStudy, UndefinedTestsAreReportedNotComputedAndTheRestStillRuns) {
  // Every take of every animator won by the montage: m_ij = 1 everywhere, so the t-tests, the
  // Shapiro-Wilk test and the mixed model are undefined (constant data); Friedman and the tests
  // over the comparisons still run.
  StudyData data;
  for (const char* a : {"A", "B", "C"}) {
    data.rankings.push_back({a, "montage", 1.0});
    data.rankings.push_back({a, "take1", 2.0});
    data.rankings.push_back({a, "take2", 3.0});
    for (int take = 1; take <= 2; ++take) {
      data.comparisons.push_back({"S1", a, take, true});
      data.comparisons.push_back({"S2", a, take, true});
    }
  }
  const StudyAnalysis a = AnalyzeStudy(data);
  EXPECT_TRUE(a.rankings.friedman.result);
  EXPECT_TRUE(a.h1.binomial.result);
  EXPECT_FALSE(a.h1.t_test.result);
  EXPECT_NE(a.h1.t_test.not_computed.find("essentially constant"), std::string::npos);
  EXPECT_FALSE(a.h3.mixed_model.result);
  EXPECT_EQ(a.ToJson()["h1"]["t_test"]["not_computed"], a.h1.t_test.not_computed);
  bool warned = false;
  for (const auto& w : a.summary.warnings) warned = warned || w.find("H1 t-test") == 0;
  EXPECT_TRUE(warned);
}

TEST(AnalyzeStudy, H2LeavesOutAnimatorsWithoutEveryTakeAndSaysSo) {
  const StudyData data = RandomStudy(3);
  const StudyAnalysis a = AnalyzeStudy(data);
  EXPECT_LT(a.h2.b.size(), 12u);
  bool warned = false;
  for (const auto& w : a.summary.warnings) warned = warned || w.find("H2 leaves out") == 0;
  EXPECT_TRUE(warned);
}

TEST(AnalyzeStudy, OptionsAreValidated) {
  StudyAnalysisOptions options;
  options.chance = 1.0;
  EXPECT_NE(test_util::ErrorOf([&] {
              AnalyzeStudy(ReadStudyData(kExample), options);
            }).find("stats.chance"),
            std::string::npos);
}

TEST(AnalyzeStudy, OutputsAreDeterministicAndTidy) {
  const StudyAnalysis a = AnalyzeStudy(ReadStudyData(kExample));
  const StudyAnalysis b = AnalyzeStudy(ReadStudyData(kExample));
  EXPECT_EQ(a.ToJson().dump(), b.ToJson().dump());
  const std::string tests = a.TestsCsv();
  EXPECT_EQ(tests.substr(0, tests.find('\n')),
            "analysis,test,statistic_name,statistic,df1,df2,p_value,estimate,conf_low,conf_high,"
            "conf_level,effect_size_name,effect_size,n");
  EXPECT_NE(tests.find("h3,mixed model F (Satterthwaite),F,"), std::string::npos);
  EXPECT_NE(tests.find(",Inf,"), std::string::npos);  // one-sided interval
  const std::string scores = a.TakeScoresCsv();
  EXPECT_EQ(std::count(scores.begin(), scores.end(), '\n'), 61);  // header + 20 x 3
}

}  // namespace
}  // namespace mmh::study

namespace mmh::study {
namespace {

// The constraint's increase on three scales, by hand (study_analysis.h): C0 = -300 and C = -294
// over n = 200 reference frames: 2 % of |C0|, 100 * 6 / (-300 + 5 * 200) = 0.857 % on the paper's
// scale (C_d = 5 - a'), 0.03 slider units per frame.
TEST(AnalyzeStudy, SegmentConstraintOnThePapersScale) {
  StudyData data = ReadStudyData(kExample);
  data.segment_costs = {{.animator = "A01",
                         .cost_unconstrained = -300,
                         .cost_constrained = -294,
                         .short_segments_unconstrained = 2,
                         .reference_frames = 200},
                        {.animator = "A02",
                         .cost_unconstrained = -100,
                         .cost_constrained = -100,
                         .short_segments_unconstrained = 0,
                         .reference_frames = 100}};
  const StudyAnalysis a = AnalyzeStudy(data);
  ASSERT_TRUE(a.segment_constraint);
  const auto& s = *a.segment_constraint;
  EXPECT_EQ(s.animators_with_short_segments, 1u);
  EXPECT_NEAR(s.max_increase_percent, 2.0, 1e-12);
  ASSERT_TRUE(s.max_paper_scale_percent && s.max_increase_per_frame);
  EXPECT_NEAR(*s.max_paper_scale_percent, 600.0 / 700.0, 1e-12);
  EXPECT_NEAR(*s.max_increase_per_frame, 0.03, 1e-12);
  EXPECT_EQ(s.threshold_scale, "paper");
  // Below 1 % on the paper's scale, although 2 % of |C0|.
  EXPECT_TRUE(s.all_below_threshold);
  EXPECT_NE(a.Report().find("on the paper's scale"), std::string::npos);
  // Without the frame counts the decision falls back to |C0| and says so.
  for (auto& row : data.segment_costs) row.reference_frames = 0;
  const StudyAnalysis b = AnalyzeStudy(data);
  EXPECT_FALSE(b.segment_constraint->max_paper_scale_percent);
  EXPECT_EQ(b.segment_constraint->threshold_scale, "relative_to_abs_c0");
  EXPECT_FALSE(b.segment_constraint->all_below_threshold);
}

}  // namespace
}  // namespace mmh::study
