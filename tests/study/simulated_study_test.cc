// The simulated study end to end in fast fidelity on a few animators: the protocol's counts, the
// analysis, determinism (per seed, independent of the thread count), the CSV round trip that
// `mmh stats` reads, replicates and power.
#include "study/simulated_study.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <set>

#include "core/config.h"
#include "core/error.h"
#include "study/figures.h"
#include "study/paper_comparison.h"
#include "tests/test_util.h"

namespace mmh::study {
namespace {

const std::string kSource = MMH_SOURCE_DIR;

Config SmallConfig(int animators, const std::string& fidelity = "fast") {
  Config config = Config::Load(kSource + "/configs/study_soldier.json");
  config.Set("scenario.story=" + kSource + "/configs/stories/soldier.json");
  config.Set("run.practice=" + kSource + "/configs/stories/mario.json");
  config.Set("run.fidelity=" + fidelity);
  config.Set("study.animators=" + std::to_string(animators));
  // 20 s of each take: the whole protocol, a third of the frames.
  config.Set("render.frames=600");
  return config;
}

// One small study shared by the tests (a fraction of a second per animator in fast fidelity).
const SimulatedStudy& SmallStudy() {
  static const SimulatedStudy study = RunSimulatedStudy(StudyConfig::FromConfig(SmallConfig(5)));
  return study;
}

TEST(SimulatedStudyTest, ProtocolCounts) {
  const SimulatedStudy& s = SmallStudy();
  ASSERT_EQ(s.animators.size(), 5u);
  EXPECT_EQ(s.design.scorers, 27);  // ceil(5 * 3 * 7 / 4)
  EXPECT_EQ(s.data.comparisons.size(), 5u * 3 * 7);
  EXPECT_EQ(s.data.rankings.size(), 5u * 4);
  EXPECT_EQ(s.data.segment_costs.size(), 5u);
  EXPECT_EQ(s.analysis.summary.animators, 5u);
  EXPECT_EQ(s.analysis.summary.self_comparisons, 0u);
  EXPECT_EQ(s.analysis.summary.takes, 3);
  EXPECT_EQ(s.rendered_frames, 0);  // fast fidelity renders nothing
  EXPECT_FALSE(s.measured_error_model.has_value());
  for (const auto& a : s.animators) {
    ASSERT_EQ(a.take_appeal.size(), 3u);
    // Skill grows from take to take (the learning rate is positive).
    EXPECT_LE(a.take_skill[0], a.take_skill[1]);
    EXPECT_LE(a.take_skill[1], a.take_skill[2]);
    EXPECT_GT(a.montage_appeal.mean_quality, 0.0);
    EXPECT_FALSE(a.montage_takes.empty());
  }
  // Every analysis of the paper is computed on five animators.
  EXPECT_TRUE(s.analysis.rankings.friedman.result.has_value());
  EXPECT_TRUE(s.analysis.h1.t_test.result.has_value());
  EXPECT_TRUE(s.analysis.h1.binomial.result.has_value());
  EXPECT_TRUE(s.analysis.h3.mixed_model.result.has_value());
  ASSERT_TRUE(s.analysis.segment_constraint.has_value());
}

std::string Fingerprint(const SimulatedStudy& s) {
  return RankingsToCsv(s.data.rankings) + ComparisonsToCsv(s.data.comparisons) +
         SegmentCostsToCsv(s.data.segment_costs) + s.analysis.ToJson().dump() +
         AnimatorsCsv(s.animators);
}

TEST(SimulatedStudyTest, DeterministicAndIndependentOfTheThreadCount) {
  const StudyConfig config = StudyConfig::FromConfig(SmallConfig(5));
  std::string one_thread;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one_thread = Fingerprint(RunSimulatedStudy(config));
  }
  EXPECT_EQ(one_thread, Fingerprint(SmallStudy()));
}

TEST(SimulatedStudyTest, CsvFilesReproduceTheAnalysis) {
  // What `mmh stats` does with the files the study writes gives the same numbers.
  const SimulatedStudy& s = SmallStudy();
  test_util::TempDir dir;
  WriteStudyData(dir.path(), s.data);
  const StudyData read = ReadStudyData(dir.path());
  const StudyAnalysis again = AnalyzeStudy(read, s.config.study.analysis);
  EXPECT_EQ(again.ToJson().dump(), s.analysis.ToJson().dump());
  EXPECT_EQ(again.TestsCsv(), s.analysis.TestsCsv());
}

TEST(SimulatedStudyTest, SegmentCostsAreTheCompositorsOwn) {
  // segment_costs.csv holds the compositor's C_T without and with the constraint, unshifted (they
  // may be negative), so the analysis' increase relative to |C0| is the compositor's own.
  const SimulatedStudy& s = SmallStudy();
  ASSERT_TRUE(s.analysis.segment_constraint.has_value());
  bool negative = false;
  for (std::size_t i = 0; i < s.animators.size(); ++i) {
    const auto& summary = s.animators[i].montage_summary;
    const auto& row = s.data.segment_costs[i];
    EXPECT_EQ(row.cost_unconstrained, summary.unconstrained_cost);
    EXPECT_EQ(row.cost_constrained, std::max(summary.total_cost, summary.unconstrained_cost));
    negative = negative || row.cost_unconstrained < 0;
    const auto& analysed = s.analysis.segment_constraint->animators[i];
    ASSERT_EQ(analysed.animator, s.animators[i].id);
    if (summary.total_cost >= summary.unconstrained_cost) {
      EXPECT_NEAR(analysed.increase_percent, summary.constraint_increase_percent, 1e-9);
    }
  }
  EXPECT_TRUE(negative);  // the liked takes of the simulated animators give C_T < 0
}

TEST(SimulatedStudyTest, ReplicatesAreIndependentSamples) {
  const StudyConfig config = StudyConfig::FromConfig(SmallConfig(5));
  const StudyConfig r0 = config.ForReplicate(0);
  const StudyConfig r1 = config.ForReplicate(1);
  const StudyConfig r2 = config.ForReplicate(2);
  EXPECT_EQ(r0.ToJson(), config.ToJson());
  std::set<std::uint64_t> seeds = {r0.run.people.population.seed, r1.run.people.population.seed,
                                   r2.run.people.population.seed};
  EXPECT_EQ(seeds.size(), 3u);
  EXPECT_NE(r1.study.seed, r0.study.seed);
  const SimulatedStudy s1 = RunSimulatedStudy(r1, 1);
  EXPECT_NE(Fingerprint(s1), Fingerprint(SmallStudy()));
  EXPECT_NE(s1.animators[0].skill, SmallStudy().animators[0].skill);

  const std::vector<StudyAnalysis> analyses = {SmallStudy().analysis, s1.analysis};
  const auto power = EstimatePower(analyses, 0.05, 0.95);
  ASSERT_EQ(power.size(), StudyHypotheses().size());
  for (std::size_t i = 0; i < power.size(); ++i) {
    const auto& p = power[i];
    int significant = 0, computed = 0;
    for (const auto& a : analyses) {
      const auto value = StudyHypotheses()[i].p_value(a);
      if (!value) continue;
      ++computed;
      significant += *value < 0.05;
    }
    EXPECT_EQ(p.replicates, computed) << p.id;
    EXPECT_EQ(p.significant, significant) << p.id;
    if (computed > 0) {
      EXPECT_LE(p.conf_low, p.power);
      EXPECT_GE(p.conf_high, p.power);
    }
  }
  // The replicates table: a header and one row per replicate, as many fields in each.
  const std::string header = ReplicatesCsvHeader();
  const std::string row = ReplicateCsvRow(1, s1.analysis);
  EXPECT_EQ(std::count(header.begin(), header.end(), ','), std::count(row.begin(), row.end(), ','));
}

TEST(SimulatedStudyTest, FiguresAndPaperTable) {
  const SimulatedStudy& s = SmallStudy();
  const auto figures = StudyFigures(s.data, s.analysis);
  ASSERT_EQ(figures.size(), 4u);
  for (const auto& f : figures) {
    EXPECT_EQ(f.svg.rfind("<?xml", 0), 0u) << f.name;
    EXPECT_NE(f.svg.find("</svg>"), std::string::npos) << f.name;
  }
  // Figure 9 has one bar per (animator, take), Figure 10 one per animator.
  auto count = [](const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (auto p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count(figures[1].svg, "<title>"), 15u);
  EXPECT_EQ(count(figures[2].svg, "<title>"), 5u);
  EXPECT_EQ(count(figures[1].csv, "\n"), 16u);
  const auto ranks = MeanRanksByItem(s.data.rankings);
  ASSERT_EQ(ranks.size(), 4u);
  EXPECT_EQ(ranks[0].item, "take1");
  EXPECT_EQ(ranks[3].item, "montage");
  double sum = 0;
  for (const auto& r : ranks) sum += r.mean_rank;
  EXPECT_DOUBLE_EQ(sum, 10.0);  // 1 + 2 + 3 + 4 per animator

  const nlohmann::json paper =
      nlohmann::json::parse(test_util::ReadBytes(kSource + "/configs/paper_reported.json"));
  const auto lines = CompareWithPaper(s.analysis, paper, 0.05, s.design.scorers);
  ASSERT_GT(lines.size(), 10u);
  EXPECT_EQ(lines[0].paper, "20");
  EXPECT_EQ(lines[0].ours, "5");
  EXPECT_THROW(CompareWithPaper(s.analysis, nlohmann::json::object(), 0.05, 1), InputError);
}

TEST(SimulatedStudyTest, BadStudyOptionsAreInputErrors) {
  Config config = SmallConfig(2);
  EXPECT_THROW(StudyConfig::FromConfig(config), InputError);
  config = SmallConfig(5);
  config.Set("study.animatorz=3");
  EXPECT_THROW(StudyConfig::FromConfig(config), InputError);
  config = SmallConfig(5);
  config.Set("scorers.count=10");
  EXPECT_THROW(StudyConfig::FromConfig(config), InputError);
  config = SmallConfig(5);
  config.Set("study.alpha=1.5");
  EXPECT_THROW(StudyConfig::FromConfig(config), InputError);
}

// Fast fidelity against full fidelity for one animator (same person, same performances): 3 takes
// of 3 s, no practice, so that the rendered and tracked version stays short for the suite (540
// frames; the montages' quality over three animators, 1 620). The study-level comparison (20
// animators, same seeds) is a documented command (docs/study.md, "Fast against full fidelity"). The
// tolerances are stated per line.
TEST(SimulatedStudyTest, FastFidelityAgreesWithFullFidelity) {
  Config config = SmallConfig(3, "full");
  config.Set("render.frames=90");
  config.Set("run.practice=\"\"");
  const StudyConfig full_config = StudyConfig::FromConfig(config);
  config.Set("run.fidelity=fast");
  const StudyConfig fast_config = StudyConfig::FromConfig(config);
  const pipeline::AnimatorRun full = pipeline::RunAnimator(full_config.run.ForAnimator(1));
  const pipeline::AnimatorRun fast = pipeline::RunAnimator(fast_config.run.ForAnimator(1));
  EXPECT_EQ(full.rendered_frames, 3 * 2 * 90);
  EXPECT_EQ(fast.rendered_frames, 0);

  // The person does not depend on the fidelity: the same takes, the same latent quality.
  ASSERT_EQ(full.takes.size(), fast.takes.size());
  std::vector<pipeline::TrackingObservation> tracking;
  std::vector<pipeline::ReadingObservation> readings;
  for (std::size_t k = 0; k < full.takes.size(); ++k) {
    const pipeline::TakeRun& take = full.takes[k];
    EXPECT_EQ(take.performed.quality.quality, fast.takes[k].performed.quality.quality);
    EXPECT_EQ(take.truth.poses.size(), fast.takes[k].tracked.poses.size());
    tracking.push_back(
        {&take.truth, &take.tracked, &take.status, take.camera_T_table.Inverse().translation});
    readings.push_back({&take.truth_annotation, &take.read_annotation, &take.slider_found});
  }
  // The error model's core parameters describe the tracker and the slider reader on these takes
  // within a factor of 2 (the defaults were measured on whole takes; these are the first 3 s).
  const pipeline::ErrorModelOptions measured =
      pipeline::EstimateErrorModel(tracking, readings, fast_config.run.error_model).options;
  const pipeline::ErrorModelOptions& model = fast_config.run.error_model;
  EXPECT_GT(measured.rotation_sd, model.rotation_sd / 2);
  EXPECT_LT(measured.rotation_sd, model.rotation_sd * 2);
  EXPECT_GT(measured.translation_sd, model.translation_sd / 2);
  EXPECT_LT(measured.translation_sd, model.translation_sd * 2);
  EXPECT_GT(measured.slider_sd, model.slider_sd / 2);
  EXPECT_LT(measured.slider_sd, model.slider_sd * 2);
  EXPECT_NEAR(measured.slider_bias, model.slider_bias, 0.15);
  // The montages show the same quality of performance within 0.1 on average over animators 1-3
  // (the montage from tracked data picks by read annotations in both modes). One animator's
  // montage is a discrete pick: animator 1 rates takes 1 and 2 within 0.02 of each other (truth
  // means −1.183 and −1.199), so the reading's noise decides between them, and full fidelity
  // picks take 2 (quality 0.300) where fast picks take 1 (0.198).
  const auto quality = [](const pipeline::AnimatorRun& run, const StudyConfig& c) {
    return people::Appraise(run.montage.trajectory, run.montage_quality, c.viewer).mean_quality;
  };
  double full_quality = quality(full, full_config), fast_quality = quality(fast, fast_config);
  for (int animator : {2, 3}) {
    full_quality +=
        quality(pipeline::RunAnimator(full_config.run.ForAnimator(animator)), full_config);
    fast_quality +=
        quality(pipeline::RunAnimator(fast_config.run.ForAnimator(animator)), fast_config);
  }
  std::printf("mean montage quality over animators 1-3: full %.3f, fast %.3f\n", full_quality / 3,
              fast_quality / 3);
  EXPECT_NEAR(full_quality / 3, fast_quality / 3, 0.1);
}

}  // namespace
}  // namespace mmh::study
