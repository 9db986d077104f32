// Speed of the simulated people (issue 4): a Soldier take performed with its latent quality, an
// annotation session of it, and a viewer's appraisal. The simulated study (issue 7) runs 60 of
// each per replicate; its fast fidelity mode needs them in well under a second. Run from a
// Release build:
//   build/bench/bench_people
// Figures and machine are recorded in bench/README.md.
#include <benchmark/benchmark.h>

#include <string>

#include "people/annotator.h"
#include "people/performance.h"
#include "people/population.h"
#include "people/viewer.h"

namespace {

using namespace mmh::people;

const Story& Soldier() {
  static const Story story =
      LoadStory(std::string(MMH_BENCH_SOURCE_DIR) + "/configs/stories/soldier.json");
  return story;
}

void BM_PerformSoldierTake(benchmark::State& state) {
  const Participant p = DrawParticipant(PopulationOptions{}, 0);
  int take = 0;
  int64_t frames = 0;
  for (auto _ : state) {
    const PerformedTake t =
        PerformTake(Soldier(), 0, p.animator, take++ % 3, PerformanceOptions{}, 1);
    frames += t.frames();
    benchmark::DoNotOptimize(t.quality.quality.data());
  }
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PerformSoldierTake)->Unit(benchmark::kMillisecond);

void BM_AnnotateSoldierTake(benchmark::State& state) {
  const Participant p = DrawParticipant(PopulationOptions{}, 0);
  const PerformedTake t = PerformTake(Soldier(), 0, p.animator, 0, PerformanceOptions{}, 1);
  std::uint64_t seed = 0;
  for (auto _ : state) {
    const AnnotationSession s =
        AnnotateTake(t.quality.quality, p.annotator, AnnotatorOptions{}, seed++);
    benchmark::DoNotOptimize(s.slider.data());
  }
  state.counters["frames/s"] = benchmark::Counter(
      static_cast<double>(t.frames()) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_AnnotateSoldierTake)->Unit(benchmark::kMillisecond);

void BM_AppraiseSoldierTake(benchmark::State& state) {
  const Participant p = DrawParticipant(PopulationOptions{}, 0);
  const PerformedTake t = PerformTake(Soldier(), 0, p.animator, 0, PerformanceOptions{}, 1);
  for (auto _ : state) {
    const Appeal a = Appraise(t.table_T_proxy, t.quality.quality, ViewerOptions{});
    benchmark::DoNotOptimize(a.appeal);
  }
  state.counters["frames/s"] = benchmark::Counter(
      static_cast<double>(t.frames()) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_AppraiseSoldierTake)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
