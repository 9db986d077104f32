// The simulated user study (`mmh study`): one replicate at fast fidelity (issue 7's target: at
// most 5 s), a few animators at full fidelity (rendered and tracked; the 20-animator study is
// timed with the command in bench/README.md), and the scoring phase and analysis alone.
//
//   build/bench/bench_study --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <string>

#include "core/config.h"
#include "study/scorers.h"
#include "study/simulated_study.h"
#include "study/study_analysis.h"

namespace {

const std::string kSource = MMH_BENCH_SOURCE_DIR;

mmh::study::StudyConfig Config(int animators, const std::string& fidelity) {
  mmh::Config config = mmh::Config::Load(kSource + "/configs/study_soldier.json");
  config.Set("scenario.story=" + kSource + "/configs/stories/soldier.json");
  config.Set("run.practice=" + kSource + "/configs/stories/mario.json");
  config.Set("run.fidelity=" + fidelity);
  config.Set("study.animators=" + std::to_string(animators));
  return mmh::study::StudyConfig::FromConfig(config);
}

void Report(benchmark::State& state, const mmh::study::SimulatedStudy& s) {
  state.counters["animators"] = static_cast<double>(s.animators.size());
  state.counters["phase1_s"] = s.animator_seconds;
  state.counters["scoring_s"] = s.scoring_seconds;
  state.counters["frames"] = static_cast<double>(s.rendered_frames);
  if (s.rendered_frames > 0) {
    state.counters["frames_per_s"] = static_cast<double>(s.rendered_frames) / s.animator_seconds;
  }
}

// One replicate of the paper's study (20 animators, 42 scorers) at fast fidelity; each iteration
// is a new replicate (new people), as in `mmh study --replicates`. metrics:1 also computes every
// animator's metrics.json (per-frame ADD/ADD-S, the truth montage), as replicate 0 of `mmh study`
// does; metrics:0 is what the replicates beyond it and `mmh calibrate`'s sweeps cost.
void BM_StudyFast(benchmark::State& state) {
  const auto config = Config(static_cast<int>(state.range(0)), "fast");
  int replicate = 0;
  for (auto _ : state) {
    auto replicate_config = config.ForReplicate(replicate);
    replicate_config.run.run.metrics = state.range(1) != 0;
    const auto s = mmh::study::RunSimulatedStudy(replicate_config, replicate);
    ++replicate;
    benchmark::DoNotOptimize(s.analysis.h1.mean_m);
    Report(state, s);
  }
}
BENCHMARK(BM_StudyFast)
    ->ArgNames({"animators", "metrics"})
    ->Args({20, 0})
    ->Args({20, 1})
    ->Unit(benchmark::kSecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// Full fidelity: every recording and annotation session rendered, tracked and read.
void BM_StudyFull(benchmark::State& state) {
  const auto config = Config(static_cast<int>(state.range(0)), "full");
  for (auto _ : state) {
    const auto s = mmh::study::RunSimulatedStudy(config);
    benchmark::DoNotOptimize(s.analysis.h1.mean_m);
    Report(state, s);
  }
}
BENCHMARK(BM_StudyFull)
    ->ArgName("animators")
    ->Arg(3)
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// Phase 2 and the analysis alone: the design, 420 judgements, 80 rankings, every test.
void BM_ScoringAndAnalysis(benchmark::State& state) {
  const mmh::study::ScorerOptions options;
  std::vector<mmh::study::AnimationAppeals> appeals(20);
  for (int i = 0; i < 20; ++i) {
    for (int k = 0; k < 3; ++k) {
      mmh::people::Appeal a;
      a.mean_quality = 0.3 + 0.02 * i + 0.05 * k;
      appeals[i].takes.push_back(a);
    }
    appeals[i].montage.mean_quality = 0.45 + 0.02 * i;
  }
  std::uint64_t seed = 1;
  for (auto _ : state) {
    const auto design = mmh::study::DrawScoringDesign(options, 20, 3, seed);
    mmh::study::StudyData data;
    data.comparisons = mmh::study::JudgeComparisons(design, appeals, {}, seed);
    data.rankings = mmh::study::RankOwnAnimations(appeals, {}, {}, seed);
    const auto analysis = mmh::study::AnalyzeStudy(data);
    benchmark::DoNotOptimize(analysis.h1.mean_m);
    ++seed;
  }
}
BENCHMARK(BM_ScoringAndAnalysis)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
