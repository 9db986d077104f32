// `mmh sweep`: parameter sweeps of run, study, compose or track, locally or as a Slurm job array
// (sweep/, docs/sweeps.md). Thin: the plan, the backends and the aggregation live in sweep/.
//   mmh sweep --spec FILE --out DIR [--jobs N] [--backend local|slurm] [--dry-run]
//   mmh sweep status DIR      mmh sweep aggregate DIR
//   mmh sweep worker DIR (--cells I,J,... | --task K)   (started by the backends)
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli/command_registry.h"
#include "cli/common_flags.h"
#include "cli/full_executable.h"
#include "core/config.h"
#include "core/error.h"
#include "pipeline/animator_run.h"
#include "sweep/command_config.h"
#include "sweep/aggregate.h"
#include "sweep/cell_store.h"
#include "sweep/local_backend.h"
#include "sweep/plan.h"
#include "sweep/slurm_backend.h"
#include "sweep/worker.h"

namespace mmh::cli {
namespace {

namespace fs = std::filesystem;

struct SweepArgs {
  CommonFlags common;
  std::string spec;
  int jobs = 1;
  std::string backend = "local";
  bool dry_run = false;
  std::string dir;         // status, aggregate, worker
  std::string cells;       // worker
  int task = -1;           // worker
  std::string slurm_bin;   // where sbatch and scontrol are ("" = PATH)
};

// Runs `mmh ARGV...` in this process, as main() would (exit codes 0, 1, 2).
int RunInProcess(const std::vector<std::string>& argv) {
  CLI::App app{"mmh"};
  app.require_subcommand(1);
  for (const RegisteredCommand& command : RegisteredCommands()) command.add(app, argv);
  std::vector<std::string> copy = argv;
  std::vector<char*> c_argv;
  for (auto& a : copy) c_argv.push_back(a.data());
  return ParseAndRun(app, static_cast<int>(c_argv.size()), c_argv.data());
}

void PrintCells(const sweep::Plan& plan) {
  for (const auto& cell : plan.cells) {
    std::string params;
    for (const auto& [k, v] : cell.params) params += " " + k + "=" + v.dump();
    std::printf("%s  point %d  replicate %d%s %s\n", cell.id.c_str(), cell.point, cell.replicate,
                cell.seed ? ("  seed " + std::to_string(*cell.seed)).c_str() : "",
                params.c_str());
  }
}

int Aggregate(const fs::path& dir, bool quiet) {
  const sweep::Plan plan = sweep::ReadPlan(dir);
  const sweep::Aggregate a = sweep::AggregateSweep(plan, dir);
  sweep::WriteAggregate(dir, a);
  if (!quiet) {
    std::printf("sweep: %d cells complete, %d failed, %d missing\nwritten: %s/{results.csv, "
                "failures.csv, summary.csv, variance_shares.csv, plots/}\n",
                a.complete, a.failed, a.missing, dir.string().c_str());
  }
  return a.failed > 0 ? 1 : 0;
}

// The light mmh runs compose sweeps and run and study sweeps in fast fidelity; the cells of track
// and of run and study in full fidelity need the renderer or the tracker: mmh-full takes over
// with the same arguments (cli/full_executable.h), and its workers are then mmh-full's.
void RequireCommandHere(sweep::SweepCommand command, const std::vector<std::string>& argv) {
  if (!HasCommand(sweep::CommandName(command))) ExecFullExecutable(argv);
}

// Hands over to mmh-full when one of `cells` renders and tracks frames and this program cannot
// (pipeline::FullFidelityLinked). Each cell's config (DIR/configs/ID.json, written by WritePlan)
// is resolved as the cell will resolve it.
void RequireCellsFidelityHere(const sweep::Plan& plan, const fs::path& dir,
                              const std::vector<int>& cells,
                              const std::vector<std::string>& argv) {
  if (pipeline::FullFidelityLinked()) return;
  for (const int c : cells) {
    const Config config = Config::Load(sweep::CellConfigPath(dir, plan.cells.at(c)));
    const nlohmann::json resolved = sweep::ResolveCommandConfig(plan.spec.command, config);
    if (sweep::NeedsFullFidelity(plan.spec.command, resolved)) ExecFullExecutable(argv);
  }
}

std::vector<int> AllCells(const sweep::Plan& plan) {
  std::vector<int> cells(plan.cells.size());
  for (std::size_t i = 0; i < cells.size(); ++i) cells[i] = static_cast<int>(i);
  return cells;
}

void RunSweep(const SweepArgs& args, const std::vector<std::string>& argv) {
  if (args.spec.empty() || args.common.out_dir.empty()) {
    throw InputError("mmh sweep needs --spec FILE and --out DIR (or: status DIR, aggregate DIR)");
  }
  if (args.backend != "local" && args.backend != "slurm") {
    ThrowBadValue("--backend", "\"" + args.backend + "\"", "local or slurm");
  }
  sweep::SweepSpec spec = sweep::LoadSpec(args.spec);
  RequireCommandHere(spec.command, argv);
  spec.sets.insert(spec.sets.end(), args.common.sets.begin(), args.common.sets.end());
  const fs::path dir = fs::absolute(args.common.out_dir).lexically_normal();
  const sweep::Plan plan = sweep::BuildPlan(spec, MMH_VERSION, fs::current_path());
  sweep::SlurmOptions slurm = spec.slurm;
  if (args.backend == "slurm") sweep::RequireSlurm(args.slurm_bin, args.dry_run);
  sweep::WritePlan(dir, plan);
  if (!args.dry_run) RequireCellsFidelityHere(plan, dir, AllCells(plan), argv);
  if (args.dry_run && !args.common.quiet) {
    PrintCells(plan);
    std::printf("%zu cells (%d settings x %d replicates); plan written to %s/plan.json\n",
                plan.cells.size(), plan.points, spec.replicates.count, dir.string().c_str());
  }
  if (args.backend == "slurm") {
    sweep::SlurmSubmitOptions submit;
    submit.slurm_bin = args.slurm_bin;
    submit.dry_run = args.dry_run;
    submit.threads = args.common.threads;
    submit.executable = fs::read_symlink("/proc/self/exe").string();
    const sweep::SlurmSubmission s = sweep::SubmitSlurm(plan, dir, submit);
    if (!args.common.quiet) std::cout << s.message;
    return;
  }
  if (args.dry_run) return;
  sweep::LocalOptions local;
  local.jobs = args.jobs;
  local.threads = args.common.threads;
  local.quiet = args.common.quiet;
  const sweep::LocalSummary s = sweep::RunLocal(plan, dir, local);
  if (!args.common.quiet) {
    std::printf("sweep: %d cells: %d done now, %d complete before, %d failed (%.1f s)\n", s.cells,
                s.done, s.skipped, s.failed, s.seconds);
  }
  if (Aggregate(dir, args.common.quiet) != 0) {
    throw std::runtime_error("some cells failed: see " + (dir / "failures.csv").string() +
                             "; run the same command again to retry them");
  }
}

void RunStatus(const SweepArgs& args) {
  const fs::path dir = fs::absolute(args.dir);
  const sweep::Plan plan = sweep::ReadPlan(dir);
  std::cout << sweep::StatusReport(plan, dir);
}

void RunWorker(const SweepArgs& args, const std::vector<std::string>& argv) {
  const fs::path dir = fs::absolute(args.dir);
  const sweep::Plan plan = sweep::ReadPlan(dir);
  RequireCommandHere(plan.spec.command, argv);
  std::vector<int> cells;
  sweep::WorkerOptions options;
  options.threads = args.common.threads > 0 ? args.common.threads : 1;
  if (args.task >= 0) {
    cells = sweep::TaskCells(dir, args.task);
    options.backend = "slurm";
  } else {
    std::size_t start = 0;
    while (start < args.cells.size()) {
      const std::size_t comma = args.cells.find(',', start);
      cells.push_back(std::stoi(args.cells.substr(start, comma - start)));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
  }
  RequireCellsFidelityHere(plan, dir, cells, argv);
  sweep::RunWorker(plan, dir, cells, options, RunInProcess);
}

}  // namespace

void AddSweepCommand(CLI::App& app, const std::vector<std::string>& argv) {
  auto args = std::make_shared<SweepArgs>();
  CLI::App* cmd = app.add_subcommand(
      "sweep", "Parameter sweeps of run, study, compose or track, locally or on Slurm");
  cmd->add_option("--spec", args->spec, "Sweep spec (configs/sweeps/*.json)");
  AddCommonFlags(
      cmd, &args->common,
      {.config_help = "",
       .set_help = "Override of every cell's base config: key.path=value, repeatable",
       .out_help = "Sweep folder (running again continues the sweep)",
       .out_required = false,
       .threads_help =
           "Threads of all cells together (default: all cores); each job gets its share"});
  cmd->add_option("--jobs", args->jobs, "Cells at a time (local backend)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--backend", args->backend, "local or slurm");
  cmd->add_flag("--dry-run", args->dry_run,
                "Print the cells and write the plan (and the Slurm script) only");
  cmd->add_option("--slurm-bin", args->slurm_bin, "Folder of sbatch/scontrol (default: PATH)");

  CLI::App* status = cmd->add_subcommand("status", "Done, failed and missing cells of a sweep");
  status->add_option("dir", args->dir, "Sweep folder")->required();
  CLI::App* aggregate =
      cmd->add_subcommand("aggregate", "results.csv, failures.csv, summary.csv and plots");
  aggregate->add_option("dir", args->dir, "Sweep folder")->required();
  aggregate->add_flag("--quiet", args->common.quiet, "Print nothing on success");
  CLI::App* worker = cmd->add_subcommand("worker", "Runs cells of a sweep (used by the backends)");
  worker->group("");  // hidden from --help
  worker->add_option("dir", args->dir, "Sweep folder")->required();
  auto* cells = worker->add_option("--cells", args->cells, "Cell indices, comma-separated");
  worker->add_option("--task", args->task, "Slurm task (manifest.json)")->excludes(cells);
  worker->add_option("--threads", args->common.threads, "Threads per cell");

  status->callback([args] { RunStatus(*args); });
  aggregate->callback([args] {
    if (Aggregate(fs::absolute(args->dir), args->common.quiet) != 0) {
      throw std::runtime_error("some cells failed: see failures.csv");
    }
  });
  worker->callback([args, argv] { RunWorker(*args, argv); });
  cmd->callback([args, cmd, argv] {
    if (!cmd->get_subcommands().empty()) return;
    RunSweep(*args, argv);
  });
}

MMH_REGISTER_COMMAND(75, AddSweepCommand);

}  // namespace mmh::cli
