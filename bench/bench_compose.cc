// Speed of the compositor (issue: "the whole compose, DTW included, in at most 30 ms on the 2-core
// machine" for 10 takes of 2700-3300 frames, d = 60). Run from a Release build:
//   build/bench/bench_compose --benchmark_counters_tabular=true
// Figures and machine are recorded in bench/README.md.
#include <benchmark/benchmark.h>

#include <map>
#include <tuple>

#include "montage/compose.h"
#include "tests/montage/oracles.h"
#include "tools/synthetic_takes.h"

namespace {

using mmh::montage::ComposeOptions;

const mmh::synthetic::TakeSet& Takes(int takes, int frames) {
  static std::map<std::pair<int, int>, mmh::synthetic::TakeSet> cache;
  auto key = std::make_pair(takes, frames);
  auto it = cache.find(key);
  if (it == cache.end()) {
    mmh::synthetic::TakeSetOptions options;
    options.takes = takes;
    options.reference_frames = frames;
    options.min_frames = frames * 9 / 10;
    options.max_frames = frames * 11 / 10;
    options.seed = 42;
    it = cache.emplace(key, mmh::synthetic::MakeTakeSet(options)).first;
  }
  return it->second;
}

// The whole compose on the standard instance and the scaling grid: args (n, m).
void BM_Compose(benchmark::State& state) {
  const auto& set = Takes(static_cast<int>(state.range(1)), static_cast<int>(state.range(0)));
  ComposeOptions options;
  mmh::montage::Montage montage;
  mmh::montage::StageTimings sum;
  for (auto _ : state) {
    montage = mmh::montage::Compose(set.takes, set.annotations, options);
    const auto& s = montage.summary.seconds;
    sum.dtw += s.dtw, sum.annotations += s.annotations, sum.smoothness += s.smoothness;
    sum.labelling += s.labelling, sum.blend += s.blend, sum.validate += s.validate;
  }
  const double runs = static_cast<double>(state.iterations());
  state.counters["dtw_ms"] = 1e3 * sum.dtw / runs;
  state.counters["smooth_ms"] = 1e3 * sum.smoothness / runs;
  state.counters["label_ms"] = 1e3 * sum.labelling / runs;
  state.counters["blend_ms"] = 1e3 * sum.blend / runs;
  state.counters["other_ms"] = 1e3 * (sum.validate + sum.annotations) / runs;
  state.counters["dtw_cells_%"] = 100 * montage.summary.dtw_cells_evaluated_share;
  state.counters["segments"] = static_cast<double>(montage.segments.size());
}
BENCHMARK(BM_Compose)
    ->ArgNames({"n", "m"})
    ->Args({3000, 10})  // the standard instance
    ->Args({750, 10})
    ->Args({1500, 10})
    ->Args({6000, 10})
    ->Args({3000, 2})
    ->Args({3000, 5})
    ->Args({3000, 20})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// One DTW of the standard instance, pruned (the default) and the full programme.
void BM_Dtw(benchmark::State& state) {
  const auto& set = Takes(10, 3000);
  mmh::montage::DtwOptions options;
  options.prune = state.range(0) != 0;
  mmh::montage::DtwResult result;
  for (auto _ : state) result = mmh::montage::ComputeDtw(set.takes[0], set.takes[1], options);
  state.counters["cells_%"] = 100.0 * result.summary.cells_evaluated / result.summary.cells_total;
}
BENCHMARK(BM_Dtw)->ArgName("prune")->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

// The labelling problem (eqs. 8, 9) of the standard instance, as Compose builds it.
mmh::montage::LabellingProblem StandardProblem() {
  const auto& set = Takes(10, 3000);
  ComposeOptions options;
  const auto montage = mmh::montage::Compose(set.takes, set.annotations, options);
  mmh::montage::LabellingProblem problem;
  problem.frames = montage.summary.reference_frames;
  problem.takes = 10;
  problem.data.resize(static_cast<std::size_t>(problem.frames) * problem.takes);
  for (int t = 0; t < problem.frames; ++t) {
    for (int l = 0; l < problem.takes; ++l) {
      problem.data[t * problem.takes + l] = -montage.warped_annotations[l][t];
    }
  }
  problem.transitions =
      mmh::montage::ComputeSmoothnessCosts(set.takes, montage.warps, options.smoothness);
  return problem;
}

// The labelling alone (constrained, d = 60) on the standard instance's costs.
void BM_Labelling(benchmark::State& state) {
  const auto problem = StandardProblem();
  mmh::montage::LabellingOptions labelling;
  labelling.min_segment_length = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(mmh::montage::SolveLabelling(problem, labelling));
}
BENCHMARK(BM_Labelling)->ArgName("d")->Arg(60)->Arg(0)->Unit(benchmark::kMillisecond);

// For comparison: the textbook O(n^2 m^2) semi-Markov programme (the tests' second oracle) on the
// same costs, d = 60.
void BM_TextbookSemiMarkov(benchmark::State& state) {
  const auto standard = StandardProblem();
  mmh::montage::oracle::Problem problem;
  problem.n = standard.frames;
  problem.m = standard.takes;
  problem.data = standard.data;
  problem.trans = standard.transitions.values;
  for (auto _ : state) {
    benchmark::DoNotOptimize(mmh::montage::oracle::SemiMarkovOptimum(problem, 100.0, 60));
  }
}
BENCHMARK(BM_TextbookSemiMarkov)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
