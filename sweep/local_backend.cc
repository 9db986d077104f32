#include "sweep/local_backend.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <deque>
#include <map>
#include <stdexcept>
#include <thread>

#include "core/atomic_file.h"
#include "core/duration_text.h"
#include "core/error.h"
#include "sweep/cell_store.h"
#include "sweep/worker.h"

namespace mmh::sweep {
namespace {

namespace fs = std::filesystem;

struct Worker {
  std::vector<int> cells;
};

pid_t SpawnWorker(const std::string& executable, const fs::path& dir, const std::vector<int>& cells,
                  int threads, const fs::path& log) {
  std::string list;
  for (int c : cells) list += (list.empty() ? "" : ",") + std::to_string(c);
  std::vector<std::string> args = {executable, "sweep",     "worker", dir.string(), "--cells",
                                   list,       "--threads", std::to_string(threads)};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const int log_fd = open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (log_fd < 0) throw std::runtime_error(log.string() + ": cannot be written");
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    // A worker dies with its sweep: a killed sweep leaves no orphan writing into DIR.
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);
    dup2(log_fd, STDOUT_FILENO);
    dup2(log_fd, STDERR_FILENO);
    const int null_fd = open("/dev/null", O_RDONLY);
    if (null_fd >= 0) dup2(null_fd, STDIN_FILENO);
    execv(executable.c_str(), argv.data());
    _exit(127);
  }
  close(log_fd);
  return pid;
}

}  // namespace

int AutoCellsPerWorker(int pending, int jobs) {
  const int batches_per_job = 4;
  const int per = (pending + jobs * batches_per_job - 1) / std::max(1, jobs * batches_per_job);
  return std::clamp(per, 1, 50);
}

LocalSummary RunLocal(const Plan& plan, const fs::path& dir, const LocalOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  LocalSummary summary;
  summary.cells = static_cast<int>(plan.cells.size());
  std::vector<int> pending;
  for (int i = 0; i < summary.cells; ++i) {
    if (ReadCellStatus(dir, plan.cells[i].id).state == CellState::kComplete) {
      ++summary.skipped;
    } else {
      ClearCellForRerun(dir, plan.cells[i].id);  // failed or half-written by a killed sweep
      pending.push_back(i);
    }
  }
  const int jobs = std::max(1, options.jobs);
  const int hardware = std::max(1u, std::thread::hardware_concurrency());
  const int total_threads = options.threads > 0 ? options.threads : hardware;
  const int threads = std::max(1, total_threads / jobs);
  int per_worker = options.cells_per_worker > 0 ? options.cells_per_worker : plan.cells_per_worker;
  if (per_worker <= 0) per_worker = AutoCellsPerWorker(static_cast<int>(pending.size()), jobs);
  const std::string executable =
      options.executable.empty() ? fs::read_symlink("/proc/self/exe").string() : options.executable;
  EnsureDirectory(dir / "logs");
  const fs::path log = dir / "logs" / "local_workers.log";

  std::deque<std::vector<int>> queue;
  for (std::size_t i = 0; i < pending.size(); i += per_worker) {
    queue.emplace_back(pending.begin() + i,
                       pending.begin() + std::min(pending.size(), i + per_worker));
  }
  const bool bar = !options.quiet && isatty(STDERR_FILENO);
  const int to_run = static_cast<int>(pending.size());
  auto progress = [&] {
    if (!bar) return;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const int finished = summary.done + summary.failed;
    const std::string eta =
        finished > 0 ? FormatDuration(elapsed / finished * (to_run - finished)) : std::string("?");
    std::fprintf(stderr, "\rsweep: %d / %d cells done, %d failed, %d skipped, ETA %s   ",
                 summary.done, to_run, summary.failed, summary.skipped, eta.c_str());
    std::fflush(stderr);
  };
  progress();

  std::map<pid_t, Worker> running;
  while (!queue.empty() || !running.empty()) {
    while (!queue.empty() && static_cast<int>(running.size()) < jobs) {
      std::vector<int> cells = std::move(queue.front());
      queue.pop_front();
      const pid_t pid = SpawnWorker(executable, dir, cells, threads, log);
      running[pid] = Worker{std::move(cells)};
    }
    int wstatus = 0;
    const pid_t pid = waitpid(-1, &wstatus, 0);
    if (pid < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error("waitpid failed");
    }
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    const std::vector<int> cells = std::move(it->second.cells);
    running.erase(it);
    // Every cell the worker finished is in its folder; the first that is not was running when
    // the worker ended (a crash or a kill): it is recorded as failed, the rest go back.
    bool crashed_cell_recorded = false;
    std::vector<int> requeue;
    for (int index : cells) {
      const Cell& cell = plan.cells[index];
      const CellStatus status = ReadCellStatus(dir, cell.id);
      if (status.state == CellState::kComplete) {
        ++summary.done;
      } else if (status.state == CellState::kFailed) {
        ++summary.failed;
      } else if (!crashed_cell_recorded) {
        crashed_cell_recorded = true;
        CellStatus failure;
        failure.exit_code = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : -1;
        if (failure.exit_code == 0) failure.exit_code = -1;
        failure.signal = WIFSIGNALED(wstatus) ? WTERMSIG(wstatus) : 0;
        const auto temps = TempCellDirs(dir, cell.id);
        std::string tail = temps.empty() ? "" : TailOfFile(temps.front() / "output.txt");
        if (tail.empty()) tail = TailOfFile(log, 5);
        failure.stderr_tail =
            tail + (tail.empty() ? "" : "\n") + "worker " + std::to_string(pid) +
            (failure.signal ? " killed by signal " + std::to_string(failure.signal)
                            : " exited with " + std::to_string(failure.exit_code)) +
            " while running this cell";
        ClearCellForRerun(dir, cell.id);
        const fs::path temp = NewTempCellDir(dir, cell.id);
        WriteStatus(temp, failure);
        PublishCell(dir, cell.id, temp);
        ++summary.failed;
      } else {
        requeue.push_back(index);
      }
    }
    if (!requeue.empty()) queue.push_front(std::move(requeue));
    progress();
  }
  if (bar) std::fprintf(stderr, "\n");
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace mmh::sweep
