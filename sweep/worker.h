// A worker runs cells of a plan one after another inside one process (the `mmh sweep worker`
// subcommand, started by the local backend or by a Slurm array task): for each cell that is not
// complete, a temporary folder, the command run in-process with its output captured, status.json
// and provenance.json, then the rename that makes the cell complete. A crash of the worker loses
// only the cell it was running; the backends record it and run the rest again.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "sweep/plan.h"

namespace mmh::sweep {

// Runs `mmh ARGV...` in this process and returns its exit code (0, 1 or 2); what it prints goes
// to this process's stdout and stderr (redirected into the cell's folder by the worker).
using CommandRunner = std::function<int(const std::vector<std::string>& argv)>;

struct WorkerOptions {
  int threads = 1;                // each cell's --threads
  std::string backend = "local";  // for provenance.json
};

// The command line of a cell (argv[0] = "mmh"), its output going to `out`.
std::vector<std::string> CellArguments(const Plan& plan, const std::filesystem::path& dir,
                                       const Cell& cell, const std::filesystem::path& out,
                                       int threads);

// Runs plan.cells[i] for each i in `cells` that is not complete. Returns the number of cells that
// failed. The environment variable MMH_SWEEP_FAULT ("kill:<id>,fail:<id>,sleep:<id>", for the
// fault tests) makes a cell end its worker with SIGKILL, fail with exit code 1, or start 8 s late.
int RunWorker(const Plan& plan, const std::filesystem::path& dir, const std::vector<int>& cells,
              const WorkerOptions& options, const CommandRunner& runner);

// The cells of each task when `per_task` cells share one worker: consecutive runs of the plan.
std::vector<std::vector<int>> PackCells(int cells, int per_task);

}  // namespace mmh::sweep
