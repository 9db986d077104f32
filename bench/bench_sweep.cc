// The sweep machinery's own cost per cell (bench/README.md): planning (resolving and hashing every
// cell's config against the command's options, writing its config), a cell's bookkeeping around
// the command (temporary folder, status.json, provenance.json, the rename, reading the status
// back) and the aggregation (reading a cell's metrics, the tables and plots). The command itself
// (compose) is measured in bench_compose.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>

#include "core/atomic_file.h"
#include "sweep/aggregate.h"
#include "sweep/cell_store.h"
#include "sweep/plan.h"
#include "sweep/spec.h"

namespace mmh::sweep {
namespace {

namespace fs = std::filesystem;

Plan ComposePlan(int cells_per_axis) {
  SweepSpec spec = LoadSpec(fs::path(MMH_BENCH_SOURCE_DIR) / "bench" / "compose_1000_cells.json");
  for (auto& axis : spec.grid) axis.values.resize(cells_per_axis);
  fs::current_path(MMH_BENCH_SOURCE_DIR);  // the spec's relative take paths
  return BuildPlan(spec, "bench", MMH_BENCH_SOURCE_DIR);
}

void BM_PlanPerCell(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(ComposePlan(10));
  state.counters["cells"] = 1000;
  state.counters["per_cell"] =
      benchmark::Counter(1000, benchmark::Counter::kIsIterationInvariantRate |
                                   benchmark::Counter::kInvert);
}
BENCHMARK(BM_PlanPerCell)->Unit(benchmark::kMillisecond);

void BM_CellBookkeeping(benchmark::State& state) {
  const fs::path dir = fs::temp_directory_path() / ("mmh_bench_sweep_" + std::to_string(getpid()));
  fs::create_directories(dir / "cells");
  int n = 0;
  for (auto _ : state) {
    const std::string id = HashHex(std::to_string(n++));
    const fs::path temp = NewTempCellDir(dir, id);
    CellStatus status;
    WriteStatus(temp, status);
    WriteFileAtomically(temp / "provenance.json", std::string(400, ' ') + "\n");
    PublishCell(dir, id, temp);
    benchmark::DoNotOptimize(ReadCellStatus(dir, id));
  }
  fs::remove_all(dir);
}
BENCHMARK(BM_CellBookkeeping)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace mmh::sweep

BENCHMARK_MAIN();
