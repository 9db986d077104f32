// The paper's user study ("User study: single object montage") on simulated people, through the
// real pipeline (`mmh study`, docs/study.md):
//
//   Phase 1  N animators (population participants 0..N−1), each through pipeline::RunAnimator:
//            the practice story (run.practice, the paper's Mario), run.takes takes of the story
//            (the Soldier), annotation with the slider block, and the montage the real
//            compositor makes from the tracked takes and the read annotations.
//   Phase 2  S scorers (the N animators among them) compare montages against takes
//            (study/scorers.h); each animator ranks their own takes and montage. Every judgement
//            is a simulated viewer's (people/viewer.h) on what was recorded: the tracked
//            trajectories with their latent quality.
//   Analysis study::AnalyzeStudy on the resulting StudyData: Friedman, H1-H3, segment costs.
//
// Replicates: replicate r > 0 derives population.seed and study.seed from (seed, r), so replicate
// 0 is the study the config describes and every replicate is an independent sample of people.
#pragma once

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/config.h"
#include "montage/compose.h"
#include "pipeline/animator_run.h"
#include "pipeline/error_model.h"
#include "people/viewer.h"
#include "study/scorers.h"
#include "study/study_analysis.h"
#include "study/study_data.h"

namespace mmh::study {

// Section "study".
struct SimulatedStudyOptions {
  // Animators (paper: 20): population participants 0..animators−1.
  int animators = 20;
  // Seed of the scoring phase (design, viewers, viewings); the people's seed is population.seed.
  std::uint64_t seed = 1;
  // Independent studies (`--replicates`); see the header comment for their seeds.
  int replicates = 1;
  // Significance level at which a replicate counts a hypothesis as supported (power).
  double alpha = 0.05;
  // The analysis (docs/statistics.md, section "stats" of `mmh stats`).
  StudyAnalysisOptions analysis;

  template <class V>
  void VisitFields(V& v) {
    v("animators", animators);
    v("seed", seed);
    v("replicates", replicates);
    v("alpha", alpha);
    v("analysis", analysis);
  }
  void Validate(const std::string& prefix) const;
};

// Everything a simulated study reads: the run sections (pipeline::RunConfig) and "study",
// "scorers", "viewer", "self_appraisal".
struct StudyConfig {
  pipeline::RunConfig run;
  SimulatedStudyOptions study;
  ScorerOptions scorers;
  people::ViewerOptions viewer;
  people::SelfAppraisalOptions self_appraisal;

  static StudyConfig FromConfig(const Config& config);
  nlohmann::json ToJson() const;
  // The config of replicate `replicate` (0: this one); seeds derived as described above.
  StudyConfig ForReplicate(int replicate) const;
};

// One animator's part of the study: what the analysis and the figures need from the run.
struct AnimatorOutcome {
  int index = 0;
  std::string id;                        // "A01", ...
  double skill = 0.0;                    // the animator's skill (before the practice)
  std::vector<double> take_skill;        // skill at each take
  std::vector<double> take_quality;      // mean latent quality of each take
  std::vector<people::Appeal> take_appeal;  // each tracked take as viewers see it
  people::Appeal montage_appeal;            // the montage of the tracked takes
  // The montage of the ground truth, for comparison (run.metrics only).
  std::optional<people::Appeal> truth_montage_appeal;
  std::vector<int> montage_takes;        // take of each montage segment
  montage::ComposeSummary montage_summary;
  std::optional<pipeline::RunMetrics> metrics;  // the run's metrics.json (run.metrics only)
  int rendered_frames = 0;
  pipeline::StageSeconds seconds;
  // Full fidelity only: the tracked takes and readings against their truth, for measuring the
  // error model (pipeline::EstimateErrorModel).
  std::vector<pipeline::TakeRun> takes;
};

struct SimulatedStudy {
  StudyConfig config;  // of this replicate
  int replicate = 0;
  std::vector<AnimatorOutcome> animators;
  ScoringDesign design;
  StudyData data;
  StudyAnalysis analysis;
  // Full fidelity: every tracked frame against its truth (tracking_errors.csv), and the error model
  // measured on them.
  std::vector<pipeline::TakeFrames> tracking_frames;
  std::optional<pipeline::ErrorModelEstimate> measured_error_model;
  double animator_seconds = 0.0;  // wall clock of phase 1
  double scoring_seconds = 0.0;   // phase 2 and the analysis
  std::int64_t rendered_frames = 0;
};

// progress(animators done, animators) from any thread, never concurrently.
using StudyProgress = std::function<void(int done, int total)>;

// Runs replicate config (as given) of the study. Animators run in parallel (oneTBB), collected in
// order: the result is independent of the thread count. Throws InputError for bad input.
SimulatedStudy RunSimulatedStudy(const StudyConfig& config, int replicate = 0,
                                 const StudyProgress& progress = {});

// The StudyData of a study from its animators' appeals and montage summaries: the design, the
// comparisons, the rankings and the segment costs. Used by RunSimulatedStudy; exposed for tests.
StudyData ScoreStudy(const StudyConfig& config, const std::vector<AnimatorOutcome>& animators,
                     ScoringDesign* design);

// ---- Replicates and power --------------------------------------------------------------------

// The hypotheses whose support a replicate records: id, and its p-value in an analysis (nullopt
// when not computed).
struct HypothesisTest {
  std::string id;           // e.g. "h1_t"
  std::string description;  // e.g. "H1: mean m_ij > 0.5, one-tailed t-test"
  std::function<std::optional<double>(const StudyAnalysis&)> p_value;
  // Whether "significant" supports the paper's claim (H3's paper result is *no* effect).
  bool paper_significant = true;
};
const std::vector<HypothesisTest>& StudyHypotheses();

struct PowerEstimate {
  std::string id;
  std::string description;
  int replicates = 0;     // replicates where the test was computed
  int significant = 0;    // of them, p < alpha
  double power = 0.0;     // significant / replicates
  double conf_low = 0.0;  // Clopper-Pearson interval (study.analysis.conf_level)
  double conf_high = 0.0;
  bool paper_significant = true;
};

std::vector<PowerEstimate> EstimatePower(const std::vector<StudyAnalysis>& analyses, double alpha,
                                         double conf_level);
nlohmann::json ToJson(const PowerEstimate& power);

// The main statistics and p-values of one replicate, in the columns of replicates.csv:
// friedman_chi_squared, h1_mean_m, h1_sd_m, h1_t, h1_wins, h2_mean_b, h2_t, h3_f, h2_sd_b,
// h2_above_chance, quick_transitions, max_increase_percent, max_paper_scale_percent, then
// p_<id> for every StudyHypotheses() test. nullopt: not computed in this replicate.
struct ReplicateStatistic {
  std::string name;
  std::optional<double> value;
};
std::vector<ReplicateStatistic> ReplicateStatistics(const StudyAnalysis& analysis);

// One row per replicate: the main statistics and p-values (replicates.csv), with header.
std::string ReplicatesCsvHeader();
std::string ReplicateCsvRow(int replicate, const StudyAnalysis& analysis);

// The animators' table (animators.csv): skill, take qualities and appeals, montage appeals,
// segment costs, rendered frames.
std::string AnimatorsCsv(const std::vector<AnimatorOutcome>& animators);

}  // namespace mmh::study
