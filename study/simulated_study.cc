#include "study/simulated_study.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <sstream>

#include "core/error.h"
#include "core/options.h"
#include "core/resource_limits.h"
#include "people/random.h"
#include "stats/binomial_test.h"
#include "stats/descriptive.h"

namespace mmh::study {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Tags of the replicate seeds.
constexpr std::uint64_t kReplicatePopulation = 0x706f70ull;  // "pop"
constexpr std::uint64_t kReplicateScoring = 0x73636full;     // "sco"

AnimatorOutcome Summarise(const StudyConfig& config, int index, pipeline::AnimatorRun run) {
  AnimatorOutcome out;
  out.index = index;
  out.id = AnimatorId(index);
  out.skill = run.participant.animator.skill;
  for (const pipeline::TakeRun& take : run.takes) {
    out.take_skill.push_back(take.performed.skill);
    out.take_quality.push_back(take.performed.MeanQuality());
    // What viewers watch: the recorded (tracked) motion; what it is worth: the performance's
    // latent quality.
    // (render.frames may shorten a recording: the quality of the recorded frames.)
    const std::vector<double>& quality = take.performed.quality.quality;
    out.take_appeal.push_back(people::Appraise(
        take.tracked,
        std::span<const double>(quality).first(std::min(quality.size(), take.tracked.size())),
        config.viewer));
  }
  out.montage_appeal = people::Appraise(run.montage.trajectory, run.montage_quality, config.viewer);
  if (config.run.run.metrics) {
    out.truth_montage_appeal =
        people::Appraise(run.truth_montage.trajectory, run.truth_montage_quality, config.viewer);
  }
  for (const auto& segment : run.montage.segments) out.montage_takes.push_back(segment.take);
  out.montage_summary = run.montage.summary;
  out.metrics = std::move(run.metrics);
  out.rendered_frames = run.rendered_frames;
  out.seconds = run.seconds;
  if (config.run.run.fidelity == pipeline::Fidelity::kFull) out.takes = std::move(run.takes);
  return out;
}

std::optional<double> POf(const auto& outcome) {
  if (!outcome.result) return std::nullopt;
  return outcome.result->p_value;
}

std::string Num(double value) { return FormatNumber(value); }

}  // namespace

void SimulatedStudyOptions::Validate(const std::string& prefix) const {
  if (animators < 3) {
    ThrowBadValue(prefix + ".animators", std::to_string(animators),
                  "at least 3 animators (the normality tests need 3)");
  }
  // Up front, not after hours: a study of 10^6 animators (a typo) would run for weeks.
  RequireAtMost(animators, kMaxPeople, prefix + ".animators", "animators");
  if (replicates < 1) {
    ThrowBadValue(prefix + ".replicates", std::to_string(replicates), "at least 1");
  }
  RequireAtMost(replicates, 10'000, prefix + ".replicates", "replicates");
  RequireFinite(alpha, prefix + ".alpha");
  if (alpha <= 0 || alpha >= 1) ThrowBadValue(prefix + ".alpha", Num(alpha), "a level in (0, 1)");
  analysis.Validate(prefix + ".analysis");
}

StudyConfig StudyConfig::FromConfig(const Config& config) {
  StudyConfig out;
  out.run = pipeline::RunConfig::FromConfig(config, {"study", "scorers", "viewer", "self_appraisal"});
  out.study = config.Get<SimulatedStudyOptions>("study");
  out.scorers = config.Get<ScorerOptions>("scorers");
  out.viewer = config.Get<people::ViewerOptions>("viewer");
  out.self_appraisal = config.Get<people::SelfAppraisalOptions>("self_appraisal");
  if (out.run.people.scenario.animator != 0) {
    ThrowBadValue("scenario.animator", std::to_string(out.run.people.scenario.animator),
                  "0 (mmh study runs participants 0 .. study.animators - 1; mmh run runs one)");
  }
  // Checked here so that a bad design fails before any animator runs.
  ScorerCount(out.scorers, out.study.animators, out.run.run.takes);
  return out;
}

nlohmann::json StudyConfig::ToJson() const {
  nlohmann::json j = run.ToJson();
  j["study"] = mmh::ToJson(study);
  j["scorers"] = mmh::ToJson(scorers);
  j["viewer"] = mmh::ToJson(viewer);
  j["self_appraisal"] = mmh::ToJson(self_appraisal);
  return j;
}

StudyConfig StudyConfig::ForReplicate(int replicate) const {
  StudyConfig out = *this;
  if (replicate == 0) return out;
  const auto r = static_cast<std::uint64_t>(replicate);
  out.run.people.population.seed =
      people::DeriveSeed(run.people.population.seed, {kReplicatePopulation, r});
  out.study.seed = people::DeriveSeed(study.seed, {kReplicateScoring, r});
  // Only replicate 0's animators are written out (results.json, animators.csv).
  out.run.run.metrics = false;
  return out;
}

StudyData ScoreStudy(const StudyConfig& config, const std::vector<AnimatorOutcome>& animators,
                     ScoringDesign* design) {
  const int n = static_cast<int>(animators.size());
  const int takes = config.run.run.takes;
  *design = DrawScoringDesign(config.scorers, n, takes, config.study.seed);
  std::vector<AnimationAppeals> appeals(n);
  for (int i = 0; i < n; ++i) {
    appeals[i].takes = animators[i].take_appeal;
    appeals[i].montage = animators[i].montage_appeal;
  }
  StudyData data;
  data.comparisons = JudgeComparisons(*design, appeals, config.viewer, config.study.seed);
  data.rankings =
      RankOwnAnimations(appeals, config.viewer, config.self_appraisal, config.study.seed);
  for (const AnimatorOutcome& a : animators) {
    const auto& s = a.montage_summary;
    // The compositor's costs as they are (negative where takes are liked: C_d = -a'(t)); the
    // constrained optimum cannot be below the unconstrained one (rounding aside).
    data.segment_costs.push_back({.animator = a.id,
                                  .cost_unconstrained = s.unconstrained_cost,
                                  .cost_constrained = std::max(s.total_cost, s.unconstrained_cost),
                                  .short_segments_unconstrained = s.unconstrained_short_segments,
                                  .reference_frames = s.reference_frames});
  }
  return data;
}

SimulatedStudy RunSimulatedStudy(const StudyConfig& config, int replicate,
                                 const StudyProgress& progress) {
  config.study.Validate("study");
  config.self_appraisal.Validate("self_appraisal");
  SimulatedStudy study;
  study.config = config;
  study.replicate = replicate;
  const int n = config.study.animators;
  ScorerCount(config.scorers, n, config.run.run.takes);

  const auto start = std::chrono::steady_clock::now();
  study.animators.resize(n);
  std::mutex progress_mutex;
  int done = 0;
  // One task per animator; RunAnimator parallelises inside too (oneTBB nests). Results land in
  // their slot, so the order (and every number) is independent of the thread count.
  tbb::parallel_for(0, n, [&](int i) {
    try {
      study.animators[i] = Summarise(config, i, pipeline::RunAnimator(config.run.ForAnimator(i)));
    } catch (const pipeline::RunError& e) {
      throw pipeline::RunError("animator " + AnimatorId(i) + " (participant " + std::to_string(i) +
                               "): " + e.what());
    }
    if (progress) {
      std::lock_guard<std::mutex> lock(progress_mutex);
      progress(++done, n);
    }
  });
  study.animator_seconds = SecondsSince(start);

  const auto scoring_start = std::chrono::steady_clock::now();
  study.data = ScoreStudy(config, study.animators, &study.design);
  study.analysis = AnalyzeStudy(study.data, config.study.analysis);
  for (const auto& a : study.animators) study.rendered_frames += a.rendered_frames;

  if (config.run.run.fidelity == pipeline::Fidelity::kFull) {
    for (const auto& a : study.animators) {
      for (pipeline::TakeFrames& take : pipeline::MeasureRunFrames(a.id, a.takes)) {
        study.tracking_frames.push_back(std::move(take));
      }
    }
    study.measured_error_model =
        pipeline::EstimateErrorModel(study.tracking_frames, config.run.error_model);
  }
  study.scoring_seconds = SecondsSince(scoring_start);
  return study;
}

const std::vector<HypothesisTest>& StudyHypotheses() {
  static const std::vector<HypothesisTest> tests = {
      {"friedman", "Rankings: the animation affects the animators' rank (Friedman)",
       [](const StudyAnalysis& a) { return POf(a.rankings.friedman); }, true},
      {"h1_t", "H1: mean m_ij > 0.5 (one-tailed t-test)",
       [](const StudyAnalysis& a) { return POf(a.h1.t_test); }, true},
      {"h1_chi_squared", "H1: montage wins over all comparisons not 50:50 (chi-squared)",
       [](const StudyAnalysis& a) { return POf(a.h1.chi_squared); }, true},
      {"h1_binomial", "H1: montage wins > 0.5 over all comparisons (exact binomial)",
       [](const StudyAnalysis& a) { return POf(a.h1.binomial); }, true},
      {"h2_t", "H2: mean b_i > 0.125 (one-tailed t-test)",
       [](const StudyAnalysis& a) { return POf(a.h2.t_test); }, true},
      {"h2_normality", "H2: b_i not normal (Shapiro-Wilk; the paper found normal)",
       [](const StudyAnalysis& a) { return POf(a.h2.normality); }, false},
      {"h3_mixed_model", "H3: take order affects m_ij (mixed model F; the paper found none)",
       [](const StudyAnalysis& a) -> std::optional<double> {
         if (!a.h3.mixed_model.result) return std::nullopt;
         return a.h3.mixed_model.result->take_test.p_value;
       },
       false},
      {"h3_residual_normality", "H3: residuals not normal (Shapiro-Wilk; the paper found normal)",
       [](const StudyAnalysis& a) { return POf(a.h3.residual_normality); }, false},
  };
  return tests;
}

std::vector<PowerEstimate> EstimatePower(const std::vector<StudyAnalysis>& analyses, double alpha,
                                         double conf_level) {
  std::vector<PowerEstimate> out;
  for (const HypothesisTest& test : StudyHypotheses()) {
    PowerEstimate p;
    p.id = test.id;
    p.description = test.description;
    p.paper_significant = test.paper_significant;
    for (const auto& analysis : analyses) {
      const auto value = test.p_value(analysis);
      if (!value) continue;
      ++p.replicates;
      if (*value < alpha) ++p.significant;
    }
    if (p.replicates > 0) {
      stats::BinomialTestOptions options;
      options.conf_level = conf_level;
      const auto ci = stats::BinomialTest(p.significant, p.replicates, options);
      p.power = ci.estimate;
      p.conf_low = ci.conf_int.lower;
      p.conf_high = ci.conf_int.upper;
    }
    out.push_back(p);
  }
  return out;
}

nlohmann::json ToJson(const PowerEstimate& p) {
  return {{"id", p.id},
          {"description", p.description},
          {"replicates", p.replicates},
          {"significant", p.significant},
          {"rate", p.power},
          {"conf_low", p.conf_low},
          {"conf_high", p.conf_high},
          {"paper_significant", p.paper_significant}};
}

std::vector<ReplicateStatistic> ReplicateStatistics(const StudyAnalysis& a) {
  std::vector<ReplicateStatistic> out;
  auto add = [&](const char* name, bool present, double value) {
    out.push_back({name, present ? std::optional<double>(value) : std::nullopt});
  };
  const auto& friedman = a.rankings.friedman.result;
  add("friedman_chi_squared", friedman.has_value(), friedman ? friedman->statistic : 0);
  add("h1_mean_m", true, a.h1.mean_m);
  add("h1_sd_m", true, a.h1.sd_m);
  const auto& h1 = a.h1.t_test.result;
  add("h1_t", h1.has_value(), h1 ? h1->t : 0);
  add("h1_wins", true, static_cast<double>(a.h1.wins));
  const auto& h2 = a.h2.t_test.result;
  add("h2_mean_b", h2.has_value(), h2 ? h2->mean : 0);
  add("h2_t", h2.has_value(), h2 ? h2->t : 0);
  const auto& h3 = a.h3.mixed_model.result;
  add("h3_f", h3.has_value(), h3 ? h3->take_test.f : 0);
  // H2's b_i: sd and how many above chance (the paper: sd 0.126, 18 of 20).
  std::vector<double> b;
  for (const auto& [animator, value] : a.h2.b) b.push_back(value);
  add("h2_sd_b", b.size() > 1, b.size() > 1 ? std::sqrt(stats::Variance(b)) : 0);
  add("h2_above_chance", true,
      static_cast<double>(std::count_if(b.begin(), b.end(), [&](double v) {
        return v > a.options.all_takes_chance;
      })));
  const auto& segments = a.segment_constraint;
  add("quick_transitions", segments.has_value(),
      segments ? static_cast<double>(segments->animators_with_short_segments) : 0);
  add("max_increase_percent", segments.has_value(), segments ? segments->max_increase_percent : 0);
  add("max_paper_scale_percent", segments && segments->max_paper_scale_percent,
      segments ? segments->max_paper_scale_percent.value_or(0) : 0);
  for (const HypothesisTest& test : StudyHypotheses()) {
    out.push_back({"p_" + test.id, test.p_value(a)});
  }
  return out;
}

std::string ReplicatesCsvHeader() {
  std::string header = "replicate";
  for (const ReplicateStatistic& s : ReplicateStatistics(StudyAnalysis{})) header += "," + s.name;
  return header + "\n";
}

std::string ReplicateCsvRow(int replicate, const StudyAnalysis& analysis) {
  std::string row = std::to_string(replicate);
  for (const ReplicateStatistic& s : ReplicateStatistics(analysis)) {
    row += ",";
    if (s.value) row += Num(*s.value);
  }
  return row + "\n";
}

std::string AnimatorsCsv(const std::vector<AnimatorOutcome>& animators) {
  std::ostringstream out;
  const int takes = animators.empty() ? 0 : static_cast<int>(animators.front().take_appeal.size());
  out << "animator,skill";
  for (int k = 1; k <= takes; ++k) {
    out << ",take" << k << "_skill,take" << k << "_quality,take" << k << "_appeal,take" << k
        << "_artefacts_per_minute";
  }
  out << ",montage_quality,montage_appeal,montage_artefacts_per_minute,truth_montage_appeal,"
         "montage_segments,montage_cost,unconstrained_cost,constraint_increase_percent,"
         "unconstrained_short_segments,rendered_frames\n";
  for (const auto& a : animators) {
    out << a.id << ',' << Num(a.skill);
    for (int k = 0; k < takes; ++k) {
      out << ',' << Num(a.take_skill[k]) << ',' << Num(a.take_quality[k]) << ','
          << Num(a.take_appeal[k].appeal) << ',' << Num(a.take_appeal[k].artefacts_per_minute);
    }
    const auto& s = a.montage_summary;
    out << ',' << Num(a.montage_appeal.mean_quality) << ',' << Num(a.montage_appeal.appeal) << ','
        << Num(a.montage_appeal.artefacts_per_minute) << ','
        << (a.truth_montage_appeal ? Num(a.truth_montage_appeal->appeal) : std::string("NA"))
        << ',' << a.montage_takes.size() << ',' << Num(s.total_cost) << ','
        << Num(s.unconstrained_cost) << ',' << Num(s.constraint_increase_percent) << ','
        << s.unconstrained_short_segments << ',' << a.rendered_frames << '\n';
  }
  return out.str();
}

}  // namespace mmh::study
