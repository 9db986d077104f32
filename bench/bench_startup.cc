// The start-up of an mmh process (docs/architecture.md, "Start-up"; issue 19, "Speed"): each
// benchmark spawns the real executable, as a shell or a sweep backend does, and waits for it. Wall
// time per process, and the child's peak resident set ("max_rss_MB", getrusage of the child).
// `mmh` is the light executable; `mmh-full` holds every command and loads every library (what
// `mmh` was before the split). MMH_BENCH_MMH=/path/to/mmh measures another build (e.g. an older
// commit's) with the same commands.
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

extern char** environ;

namespace {

namespace fs = std::filesystem;

std::string Mmh() {
  const char* other = std::getenv("MMH_BENCH_MMH");
  return other != nullptr ? other : MMH_BENCH_BINARY;
}

std::string MmhFull() { return (fs::path(Mmh()).parent_path() / "mmh-full").string(); }

// Runs `args` (args[0] the executable) with stdout and stderr to /dev/null, in the source tree (the
// example takes' relative paths); returns the child's peak resident set in bytes. Exit status
// other than 0 is an error.
double Spawn(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int error = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (error != 0) throw std::runtime_error("cannot start " + args[0]);
  int status = 0;
  rusage usage{};
  if (wait4(pid, &status, 0, &usage) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    throw std::runtime_error(args[0] + " " + args[1] + " failed");
  }
  return usage.ru_maxrss * 1024.0;
}

void Measure(benchmark::State& state, const std::vector<std::string>& args) {
  fs::current_path(MMH_BENCH_SOURCE_DIR);
  double rss = 0;
  for (auto _ : state) rss = std::max(rss, Spawn(args));
  state.counters["max_rss_MB"] = rss / 1e6;
}

// A sweep folder with the plan of configs/sweeps/compose_synthetic.json (75 compose cells),
// cell 0 complete.
fs::path SweepDir() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("mmh_bench_startup_" + std::to_string(getpid()));
    fs::remove_all(d);
    fs::current_path(MMH_BENCH_SOURCE_DIR);
    Spawn({Mmh(), "sweep", "--spec", "configs/sweeps/compose_synthetic.json", "--out", d.string(),
           "--dry-run", "--quiet"});
    Spawn({Mmh(), "sweep", "worker", d.string(), "--cells", "0"});
    return d;
  }();
  return dir;
}

const std::vector<std::string> kComposeInputs = {
    "--takes", "examples/synthetic_story/take_1.tum", "examples/synthetic_story/take_2.tum",
    "examples/synthetic_story/take_3.tum", "--annotations", "examples/synthetic_story/take_1.csv",
    "examples/synthetic_story/take_2.csv", "examples/synthetic_story/take_3.csv"};

void BM_Version(benchmark::State& state) { Measure(state, {Mmh(), "--version"}); }
BENCHMARK(BM_Version)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_VersionFull(benchmark::State& state) { Measure(state, {MmhFull(), "--version"}); }
BENCHMARK(BM_VersionFull)->Unit(benchmark::kMillisecond)->UseRealTime();

// A command that mmh hands to mmh-full: the exec's cost on top of mmh-full's.
void BM_HelpOfRunViaExec(benchmark::State& state) { Measure(state, {Mmh(), "run", "--help"}); }
BENCHMARK(BM_HelpOfRunViaExec)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_SweepStatus(benchmark::State& state) {
  Measure(state, {Mmh(), "sweep", "status", SweepDir().string()});
}
BENCHMARK(BM_SweepStatus)->Unit(benchmark::kMillisecond)->UseRealTime();

// The whole command: start-up, reading 3 takes of ~1000 frames, Compose(), writing the folder
// (montage.glb included).
void BM_Compose(benchmark::State& state) {
  const fs::path out = fs::temp_directory_path() / ("mmh_bench_compose_" + std::to_string(getpid()));
  std::vector<std::string> args = {Mmh(), "compose"};
  args.insert(args.end(), kComposeInputs.begin(), kComposeInputs.end());
  args.insert(args.end(), {"--out", out.string(), "--quiet"});
  Measure(state, args);
  fs::remove_all(out);
}
BENCHMARK(BM_Compose)->Unit(benchmark::kMillisecond)->UseRealTime();

// Start-up and the command line only: prints the subcommand's help.
void BM_ComposeHelp(benchmark::State& state) { Measure(state, {Mmh(), "compose", "--help"}); }
BENCHMARK(BM_ComposeHelp)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Stats(benchmark::State& state) {
  const fs::path out = fs::temp_directory_path() / ("mmh_bench_stats_" + std::to_string(getpid()));
  Measure(state, {Mmh(), "stats", "--input", "examples/study_data", "--out", out.string(),
                  "--quiet"});
  fs::remove_all(out);
}
BENCHMARK(BM_Stats)->Unit(benchmark::kMillisecond)->UseRealTime();

// A whole fast-fidelity command, `mmh run` on configs/soldier.json (3 Soldier takes: the error
// model on the ground truth, both montages, metrics.json, montage.glb) or `mmh study` on
// configs/study_soldier.json (20 animators, one study, run.metrics off as its replicates have
// it), in the light mmh and in mmh-full: the same work and bytes (StartupTest), so the
// difference is the start-up. One thread, as a sweep cell runs.
void Fast(benchmark::State& state, const std::string& executable, const std::string& command,
          const std::string& config) {
  const fs::path out =
      fs::temp_directory_path() / ("mmh_bench_" + command + "_" + std::to_string(getpid()));
  std::vector<std::string> args = {executable, command, "--config", config, "--set",
                                   "run.fidelity=\"fast\"", "--threads", "1", "--quiet",
                                   "--out", out.string()};
  if (command == "study") args.insert(args.end(), {"--set", "run.metrics=false"});
  Measure(state, args);
  fs::remove_all(out);
}
void BM_RunFast(benchmark::State& state) { Fast(state, Mmh(), "run", "configs/soldier.json"); }
BENCHMARK(BM_RunFast)->Unit(benchmark::kMillisecond)->UseRealTime();
void BM_RunFastFull(benchmark::State& state) {
  Fast(state, MmhFull(), "run", "configs/soldier.json");
}
BENCHMARK(BM_RunFastFull)->Unit(benchmark::kMillisecond)->UseRealTime();
void BM_StudyFast(benchmark::State& state) {
  Fast(state, Mmh(), "study", "configs/study_soldier.json");
}
BENCHMARK(BM_StudyFast)->Unit(benchmark::kMillisecond)->UseRealTime();
void BM_StudyFastFull(benchmark::State& state) {
  Fast(state, MmhFull(), "study", "configs/study_soldier.json");
}
BENCHMARK(BM_StudyFastFull)->Unit(benchmark::kMillisecond)->UseRealTime();

// A sweep worker running one compose cell: start-up, reading the plan, the cell (compose on the 4
// example takes, in-process) and its bookkeeping. The cell's folder is removed between runs (a
// worker skips complete cells).
void BM_SweepWorkerComposeCell(benchmark::State& state) {
  const fs::path dir = SweepDir();
  fs::current_path(MMH_BENCH_SOURCE_DIR);
  double rss = 0;
  for (auto _ : state) {
    state.PauseTiming();
    fs::remove_all(dir / "cells");
    fs::create_directories(dir / "cells");
    state.ResumeTiming();
    rss = std::max(rss, Spawn({Mmh(), "sweep", "worker", dir.string(), "--cells", "1"}));
  }
  state.counters["max_rss_MB"] = rss / 1e6;
}
BENCHMARK(BM_SweepWorkerComposeCell)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  std::error_code ignored;
  fs::remove_all(fs::temp_directory_path() / ("mmh_bench_startup_" + std::to_string(getpid())),
                 ignored);
  return 0;
}
