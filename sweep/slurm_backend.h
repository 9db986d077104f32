// The Slurm backend: the plan's cells packed into tasks (DIR/slurm/manifest.json), a job-array
// script that runs one task per array index (`mmh sweep worker DIR --task K`, one log per task in
// DIR/logs/, --requeue: a preempted task redoes its incomplete cells and skips complete ones),
// arrays split where they would exceed the cluster's MaxArraySize, a `%K` throttle, and the
// aggregation queued after the arrays (--dependency=afterany). Only the tasks that still have
// missing or failed cells are submitted, so running the same command again resubmits exactly
// those.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "sweep/plan.h"

namespace mmh::sweep {

struct SlurmSubmitOptions {
  std::string slurm_bin;   // folder of sbatch and scontrol ("" = the PATH)
  bool dry_run = false;    // write the scripts and print the commands only
  int threads = 0;         // --cpus-per-task and each cell's --threads (0: 1)
  std::string executable;  // the mmh binary the tasks run
};

struct SlurmSubmission {
  std::vector<std::string> array_job_ids;
  std::string aggregate_job_id;
  int tasks_submitted = 0;
  std::string message;  // what was written and submitted, for the user
};

// InputError naming the PATH (or --slurm-bin) when sbatch cannot be found (unless dry_run).
void RequireSlurm(const std::string& slurm_bin, bool dry_run);

SlurmSubmission SubmitSlurm(const Plan& plan, const std::filesystem::path& dir,
                            const SlurmSubmitOptions& options);

// The cells of task `task` (manifest.json).
std::vector<int> TaskCells(const std::filesystem::path& dir, int task);

// Done / failed / missing cells, the failures' last lines, and (for a Slurm sweep) the --array=
// list of every array chunk that resubmits exactly the tasks with missing or failed cells.
std::string StatusReport(const Plan& plan, const std::filesystem::path& dir);

// "0-3,7,9-10": indices as Slurm's --array ranges (sorted, unique).
std::string ArrayRanges(const std::vector<int>& indices);

}  // namespace mmh::sweep
