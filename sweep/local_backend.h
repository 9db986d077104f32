// The local backend: worker processes (`mmh sweep worker`) on this machine, `jobs` at a time,
// each with its share of the threads. A worker that crashes or is killed costs only the cell it
// was running (recorded as failed with its signal and the tail of its output); the rest of its
// cells go back to the queue. Progress (done / failed / ETA) on a terminal, nothing under quiet.
#pragma once

#include <filesystem>
#include <string>

#include "sweep/plan.h"

namespace mmh::sweep {

struct LocalOptions {
  int jobs = 1;              // worker processes at a time
  int threads = 0;           // all workers together (0: the machine's cores)
  int cells_per_worker = 0;  // 0: the plan's (packing short cells)
  bool quiet = false;
  std::string executable;  // the mmh binary ("" = this process's)
};

struct LocalSummary {
  int cells = 0;
  int skipped = 0;  // complete before this run
  int done = 0;     // completed by this run
  int failed = 0;   // failed in this run
  double seconds = 0.0;
};

LocalSummary RunLocal(const Plan& plan, const std::filesystem::path& dir,
                      const LocalOptions& options);

// Cells per worker when the plan leaves it to the backend: short cells packed so that each of
// `jobs` workers gets several batches (load balance) and a batch stays small (a crash loses one
// cell, a batch bounds the requeue).
int AutoCellsPerWorker(int pending, int jobs);

}  // namespace mmh::sweep
