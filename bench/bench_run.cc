// Speed of one animator end to end (issue 6): the full Soldier animator (3 takes of about 2000
// frames, each recorded and annotated through the Kinect model, the tracker and the slider reader,
// both montages and the metrics) must take at most 30 s on the 2-core machine, i.e. at least
// 400 frames per second through render and track together. Also: the same animator in fast
// fidelity (the error model instead of frames), and a quarter of the frames with one thread, for
// the per-frame cost. Run from a Release build:
//   build/bench/bench_run --benchmark_counters_tabular=true
// Figures and machine are recorded in bench/README.md.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <memory>
#include <string>

#include "core/config.h"
#include "pipeline/animator_run.h"

namespace {

using namespace mmh;

pipeline::RunConfig SoldierConfig(const std::string& fidelity, int frames) {
  Config config = Config::Load(std::string(MMH_BENCH_SOURCE_DIR) + "/configs/soldier.json");
  config.Set(std::string("scenario.story=\"") + MMH_BENCH_SOURCE_DIR +
             "/configs/stories/soldier.json\"");
  config.Set("run.fidelity=" + fidelity);
  config.Set("render.frames=" + std::to_string(frames));
  return pipeline::RunConfig::FromConfig(config);
}

// state.range(0): frames per take (0: whole takes); state.range(1): threads (0: all).
void BM_SoldierAnimator(benchmark::State& state) {
  const pipeline::RunConfig config = SoldierConfig("full", static_cast<int>(state.range(0)));
  std::unique_ptr<tbb::global_control> limit;
  if (state.range(1) > 0) {
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                  state.range(1));
  }
  double frames = 0, sessions = 0, record = 0, annotate = 0;
  for (auto _ : state) {
    const pipeline::AnimatorRun run = pipeline::RunAnimator(config);
    frames += run.rendered_frames;
    sessions += run.seconds.record + run.seconds.annotate;
    record += run.seconds.record;
    annotate += run.seconds.annotate;
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["frames"] = frames / n;
  state.counters["render+track fps"] = sessions > 0 ? frames / sessions : 0;
  state.counters["record s"] = record / n;
  state.counters["annotate s"] = annotate / n;
}
BENCHMARK(BM_SoldierAnimator)
    ->ArgsProduct({{0}, {0}})
    ->Args({500, 1})
    ->ArgNames({"frames", "threads"})
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

void BM_SoldierAnimatorFast(benchmark::State& state) {
  const pipeline::RunConfig config = SoldierConfig("fast", 0);
  int animator = 0;
  for (auto _ : state) {
    const pipeline::AnimatorRun run = pipeline::RunAnimator(config.ForAnimator(animator++ % 20));
    benchmark::DoNotOptimize(run.metrics->takes.size());
  }
}
BENCHMARK(BM_SoldierAnimatorFast)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
